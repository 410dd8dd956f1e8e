# rcfd_embed_files(OUT_VAR FILES...)
# Generates a C++ source that holds the given text files (JSON Schemas, example scenes) as string
# constants, so binaries work from any directory and the schemas in schemas/ stay the single source.
# It defines rcfd::embeddedFiles() (core/EmbeddedFiles.hpp), keyed by the path relative to the project.
function(rcfd_embed_files out_var)
  rcfd_embed_files_as(generated embedded_files core/EmbeddedFiles.hpp rcfd embeddedFiles ${ARGN})
  set(${out_var} "${generated}" PARENT_SCOPE)
endfunction()

# rcfd_embed_files_as(OUT_VAR STEM HEADER NAMESPACE FUNCTION FILES...)
# The same for another set of files (the server's web page): writes STEM.cpp defining
# NAMESPACE::FUNCTION(), declared in HEADER as
# const std::map<std::string, std::string_view>& FUNCTION();
function(rcfd_embed_files_as out_var stem header namespace function)
  set(out "${CMAKE_CURRENT_BINARY_DIR}/${stem}.cpp")
  # A ";" list would be split into separate shell commands: pass the files "|"-separated (VERBATIM
  # quotes the "|" for the shell).
  string(REPLACE ";" "|" files_arg "${ARGN}")
  add_custom_command(
    OUTPUT "${out}"
    COMMAND ${CMAKE_COMMAND} -DOUT=${out} "-DFILES=${files_arg}" -DBASE=${PROJECT_SOURCE_DIR}
            -DHEADER=${header} -DNAMESPACE=${namespace} -DFUNCTION=${function}
            -P ${PROJECT_SOURCE_DIR}/cmake/EmbedFilesScript.cmake
    DEPENDS ${ARGN} ${PROJECT_SOURCE_DIR}/cmake/EmbedFilesScript.cmake
    COMMENT "Embedding ${stem}"
    VERBATIM)
  set(${out_var} "${out}" PARENT_SCOPE)
endfunction()
