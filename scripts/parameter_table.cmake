# A stage's parameter table (terrain/parameter.h) is data beside the stage:
# NAME_parameters.toml in the stage's folder. This file turns it into the C++
# definition of `NAME_parameters()` at configure time, binding each row to its
# options struct's field by the row's own `field` (a misspelt field does not
# compile). The file is a strict subset of TOML, read line by line; a line it
# cannot read stops the configure naming the file and the line.
#
#   header = "terrain/soil/soil_parameters.h"   # declares NAME_parameters()
#   namespace = "drift::soil"
#   options = "SoilOptions"                      # the struct the rows set
#   # a whole-line comment
#   [[parameter]]
#   field = "soil.phi_deg"     # the struct's member, as errors name it
#   flag = "--phi"             # optional: the command line's flag
#   range = "[0, 60)"          # [ or ( then lo, hi (a number or inf), ] or )
#   integer = true             # optional: a whole number
#   unit = "degrees"           # optional
#   meaning = "angle of internal friction phi"
#   key = "[soil] phi"         # optional: the key in a scene or scenario file
#
# Used two ways: include() it and call drift_parameter_tables(target) in a
# stage's CMakeLists.txt (every *_parameters.toml beside it joins `target`), or
# `cmake -DTOML=in.toml -DOUT=out.cpp -P parameter_table.cmake`
# (tests/parameter_tables).

if(CMAKE_SCRIPT_MODE_FILE)
  cmake_minimum_required(VERSION 3.25)  # the policies of the build's own run
endif()

# Writes the C++ of the table in `toml` to `out`.
function(drift_parameter_table_source toml out)
  get_filename_component(name ${toml} NAME_WE)
  file(READ ${toml} text)
  # One list item a line. ';', '[' and ']' would split or join list items, so
  # they travel as placeholders until written out.
  string(REPLACE ";" "<SC>" text "${text}")
  string(REPLACE "[" "<LB>" text "${text}")
  string(REPLACE "]" "<RB>" text "${text}")
  string(REPLACE "\n" ";" lines "${text}")
  set(number "[-+]?[0-9][0-9.eE+-]*")
  set(string_value "\"([^\"\\\\]|\\\\.)*\"")
  set(rows "")
  set(in_row FALSE)
  foreach(key IN ITEMS header namespace options)
    set(top_${key} "")
  endforeach()
  # A sentinel line closes the last row.
  list(APPEND lines "<LB><LB>parameter<RB><RB>")
  foreach(line IN LISTS lines)
    string(STRIP "${line}" line)
    if(line STREQUAL "" OR line MATCHES "^#")
      continue()
    elseif(line STREQUAL "<LB><LB>parameter<RB><RB>")
      if(in_row)
        foreach(required IN ITEMS field range meaning)
          if(row_${required} STREQUAL "")
            message(FATAL_ERROR "${toml}: the row of field ${row_field} has no ${required}")
          endif()
        endforeach()
        string(APPEND rows "    {${row_field}, ${row_flag}, ${row_lo}, ${row_hi}, Ends::${row_ends}, "
               "${row_integer}, ${row_unit}, ${row_meaning}, "
               "DRIFT_PARAMETER_FIELD(${top_options}, ${row_member}), ${row_key}},\n")
      endif()
      set(in_row TRUE)
      foreach(key IN ITEMS field range meaning member lo hi ends)
        set(row_${key} "")
      endforeach()
      set(row_flag "\"\"")
      set(row_unit "\"\"")
      set(row_key "\"\"")
      set(row_integer false)
    elseif(line MATCHES "^([a-z]+) = (${string_value}|true|false)$")
      set(key ${CMAKE_MATCH_1})
      set(value "${CMAKE_MATCH_2}")
      if(NOT in_row AND key MATCHES "^(header|namespace|options)$" AND value MATCHES "^\"")
        string(REGEX REPLACE "^\"(.*)\"$" "\\1" top_${key} "${value}")
      elseif(in_row AND key MATCHES "^(flag|unit|meaning|key)$" AND value MATCHES "^\"")
        set(row_${key} "${value}")
      elseif(in_row AND key STREQUAL "integer" AND NOT value MATCHES "^\"")
        set(row_integer ${value})
      elseif(in_row AND key STREQUAL "field" AND value MATCHES "^\"([A-Za-z_][A-Za-z0-9_.]*)\"$")
        set(row_member ${CMAKE_MATCH_1})
        set(row_field "${value}")
      elseif(in_row AND key STREQUAL "range" AND value MATCHES
             "^\"(<LB>|\\()(${number}), (${number}|inf)(<RB>|\\))\"$")
        set(row_range "${value}")
        set(row_lo ${CMAKE_MATCH_2})
        set(row_hi ${CMAKE_MATCH_3})
        set(low_open FALSE)
        set(high_open FALSE)
        if(CMAKE_MATCH_1 STREQUAL "(")
          set(low_open TRUE)
        endif()
        if(CMAKE_MATCH_4 STREQUAL ")")
          set(high_open TRUE)
        endif()
        if(low_open AND high_open)
          set(row_ends Open)
        elseif(low_open)
          set(row_ends OpenLow)
        elseif(high_open)
          set(row_ends OpenHigh)
        else()
          set(row_ends Closed)
        endif()
      else()
        message(FATAL_ERROR "${toml}: cannot read '${line}' here (placeholders <LB> <RB> <SC> "
                "stand for [ ] ;); see scripts/parameter_table.cmake for the keys and values")
      endif()
    else()
      message(FATAL_ERROR "${toml}: cannot read '${line}' (placeholders <LB> <RB> <SC> stand for "
              "[ ] ;); write key = \"text\", true or false, a whole-line # comment or "
              "<LB><LB>parameter<RB><RB>")
    endif()
  endforeach()
  foreach(key IN ITEMS header namespace options)
    if(top_${key} STREQUAL "")
      message(FATAL_ERROR "${toml}: no ${key} = \"...\" before the first row")
    endif()
  endforeach()
  get_filename_component(file ${toml} NAME)
  set(source "// Generated from ${file} by scripts/parameter_table.cmake: edit that file.\n")
  string(APPEND source "#include \"${top_header}\"\n\n#include <limits>\n\n"
         "namespace ${top_namespace} {\n\n"
         "const std::vector<terrain::Parameter<${top_options}>>& ${name}() {\n"
         "  using terrain::Ends;\n"
         "  [[maybe_unused]] constexpr double inf = std::numeric_limits<double>::infinity();\n"
         "  static const std::vector<terrain::Parameter<${top_options}>> table = {\n"
         "${rows}  };\n  return table;\n}\n\n}  // namespace ${top_namespace}\n")
  string(REPLACE "<SC>" ";" source "${source}")
  string(REPLACE "<LB>" "[" source "${source}")
  string(REPLACE "<RB>" "]" source "${source}")
  # Written only when it changes, so that a configure rebuilds nothing else.
  file(WRITE ${out}.new "${source}")
  file(COPY_FILE ${out}.new ${out} ONLY_IF_DIFFERENT)
  file(REMOVE ${out}.new)
endfunction()

# Adds every *_parameters.toml beside the calling CMakeLists.txt to `target`;
# editing one reruns the configure.
function(drift_parameter_tables target)
  file(GLOB tables CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*_parameters.toml)
  foreach(toml IN LISTS tables)
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${toml})
    get_filename_component(name ${toml} NAME_WE)
    set(out ${CMAKE_CURRENT_BINARY_DIR}/${name}_table.cpp)
    drift_parameter_table_source(${toml} ${out})
    target_sources(${target} PRIVATE ${out})
  endforeach()
endfunction()

if(CMAKE_SCRIPT_MODE_FILE AND DEFINED TOML AND DEFINED OUT)
  drift_parameter_table_source(${TOML} ${OUT})
endif()
