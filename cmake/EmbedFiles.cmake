# rcfd_embed_files(TARGET_SOURCE_VAR NAMESPACE FILES...)
# Generates a C++ source that holds the given text files (JSON Schemas, example scenes) as string
# constants, so binaries work from any directory and the schemas in schemas/ stay the single source.
function(rcfd_embed_files out_var)
  set(out "${CMAKE_CURRENT_BINARY_DIR}/embedded_files.cpp")
  # A ";" list would be split into separate shell commands: pass the files "|"-separated (VERBATIM
  # quotes the "|" for the shell).
  string(REPLACE ";" "|" files_arg "${ARGN}")
  add_custom_command(
    OUTPUT "${out}"
    COMMAND ${CMAKE_COMMAND} -DOUT=${out} "-DFILES=${files_arg}" -DBASE=${PROJECT_SOURCE_DIR}
            -P ${PROJECT_SOURCE_DIR}/cmake/EmbedFilesScript.cmake
    DEPENDS ${ARGN} ${PROJECT_SOURCE_DIR}/cmake/EmbedFilesScript.cmake
    COMMENT "Embedding schemas and examples"
    VERBATIM)
  set(${out_var} "${out}" PARENT_SCOPE)
endfunction()
