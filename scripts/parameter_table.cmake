# A stage's parameter table (terrain/parameter.h) is data beside the stage:
# NAME_parameters.toml in the stage's folder. drift_parameter_tables(target)
# turns each into the C++ definition of `NAME_parameters()` at build time,
# with the generator scripts/parameter_table.cpp (toml++; its opening comment
# gives the table's keys), binding each row to its options struct's field by
# the row's own `field` (a misspelt field does not compile). A table it
# cannot read stops the build naming the file, the line and the key
# (tests/parameter_tables).

# The generator, a host tool of the build (built once, before the libraries
# whose tables it writes).
if(NOT TARGET drift_parameter_table)
  add_executable(drift_parameter_table ${CMAKE_CURRENT_LIST_DIR}/parameter_table.cpp)
  target_link_libraries(drift_parameter_table PRIVATE tomlplusplus::tomlplusplus drift_warnings)
  # terrain/json_text.h (header only): its string literals are C++'s too.
  target_include_directories(drift_parameter_table PRIVATE ${PROJECT_SOURCE_DIR})
endif()

# Generates `out` from the table `toml` at build time, as a source of `target`.
function(drift_generated_table target toml out)
  get_filename_component(file ${toml} NAME)
  get_filename_component(written ${out} NAME)
  add_custom_command(OUTPUT ${out}
                     COMMAND drift_parameter_table ${toml} ${out}
                     DEPENDS drift_parameter_table ${toml}
                     COMMENT "Generating ${written} from ${file}"
                     VERBATIM)
  target_sources(${target} PRIVATE ${out})
endfunction()

# Adds every *_parameters.toml beside the calling CMakeLists.txt to `target`,
# generated into the build folder as NAME_table.cpp; editing one regenerates
# it (and rebuilds only what changed).
function(drift_parameter_tables target)
  file(GLOB tables CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*_parameters.toml)
  foreach(toml IN LISTS tables)
    get_filename_component(name ${toml} NAME_WE)
    drift_generated_table(${target} ${toml} ${CMAKE_CURRENT_BINARY_DIR}/${name}_table.cpp)
  endforeach()
endfunction()

# A subcommand's flags kept as data, cmd_NAME_flags.toml beside the calling
# CMakeLists.txt: generated into the build folder as cmd_NAME_flags.inc, the
# definition of its flags function, which cmd_NAME.cpp includes as
# "FOLDER/cmd_NAME_flags.inc".
function(drift_flag_tables target)
  file(GLOB tables CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/cmd_*_flags.toml)
  foreach(toml IN LISTS tables)
    get_filename_component(name ${toml} NAME_WE)
    drift_generated_table(${target} ${toml} ${CMAKE_CURRENT_BINARY_DIR}/${name}.inc)
  endforeach()
  target_include_directories(${target} PRIVATE ${PROJECT_BINARY_DIR})
endfunction()
