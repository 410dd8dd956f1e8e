# Hot kernels compiled once more for AVX-512 in a portable build (core/Isa.hpp, docs/architecture.md).
#
# rcfd_add_kernel_variant(TARGET ISA FLAGS ... SOURCES ...) compiles SOURCES, which TARGET already
# compiles for the build's baseline, a second time with FLAGS and RCFD_KERNEL_VARIANT_<ISA> defined
# (core/IsaNamespace.hpp puts their kernels in namespace isa_<isa>), and adds the objects to TARGET.
#
# The variant's own functions are in their own namespace, but the inline functions and templates it
# instantiates from other headers (Eigen, the standard library, rcfd's own) are weak symbols with the
# same names as the baseline's copies, and the linker keeps one copy of each for the whole program: it
# could keep the AVX-512 one and run it on a CPU without AVX-512. So the variant's objects are first
# linked into one (ld -r) and every weak function and vtable they define is renamed with the suffix
# ".isa_<isa>" (cmake/RenameWeakSymbols.cmake): the variant calls its own copies, everyone else the
# baseline's. Weak data (static locals, template statics) keeps its name: there is one of each.
function(rcfd_add_kernel_variant target isa)
  cmake_parse_arguments(PARSE_ARGV 2 V "" "" "FLAGS;SOURCES")
  string(TOUPPER "${isa}" upper)
  set(objects ${target}_kernels_${isa})
  add_library(${objects} OBJECT ${V_SOURCES})
  target_compile_options(${objects} PRIVATE ${V_FLAGS})
  target_compile_definitions(${objects} PRIVATE RCFD_KERNEL_VARIANT_${upper}=1
                             $<TARGET_PROPERTY:${target},COMPILE_DEFINITIONS>)
  target_include_directories(${objects} PRIVATE $<TARGET_PROPERTY:${target},INCLUDE_DIRECTORIES>)
  target_link_libraries(${objects} PRIVATE $<TARGET_PROPERTY:${target},LINK_LIBRARIES>)
  set(renamed ${CMAKE_CURRENT_BINARY_DIR}/${objects}.o)
  add_custom_command(
    OUTPUT ${renamed}
    COMMAND ${CMAKE_COMMAND} "-DOBJECTS=$<JOIN:$<TARGET_OBJECTS:${objects}>,|>" -DOUTPUT=${renamed}
            -DSUFFIX=isa_${isa} -DCXX=${CMAKE_CXX_COMPILER} -DNM=${CMAKE_NM} -DOBJCOPY=${CMAKE_OBJCOPY}
            -P ${PROJECT_SOURCE_DIR}/cmake/RenameWeakSymbols.cmake
    DEPENDS ${objects} $<TARGET_OBJECTS:${objects}> ${PROJECT_SOURCE_DIR}/cmake/RenameWeakSymbols.cmake
    COMMENT "Renaming the weak symbols of the ${isa} kernels"
    VERBATIM)
  target_sources(${target} PRIVATE ${renamed})
  set_source_files_properties(${renamed} PROPERTIES EXTERNAL_OBJECT TRUE GENERATED TRUE)
endfunction()
