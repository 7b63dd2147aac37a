# The message catalogues compiled into rwcalc: po/ru.po becomes generated/catalog_ru.cpp, one
# function returning the file's text, which src/core/i18n.cpp reads on first use. Editing the .po
# file re-runs this at the next build (a configure dependency).
function(rwcalc_embed_catalogue target po out)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${po})
  file(READ ${po} text)
  string(FIND "${text}" ")rwcalc_po\"" clash)
  if(NOT clash EQUAL -1)
    message(FATAL_ERROR "${po} contains the raw-string delimiter )rwcalc_po\"")
  endif()
  file(WRITE ${out}.tmp
       "// Generated from ${po} by cmake/catalog.cmake: edit the .po file, not this one.\n"
       "#include <string_view>\nnamespace rwcalc {\nstd::string_view embedded_russian_po() {\n"
       "  static constexpr std::string_view text = R\"rwcalc_po(" "${text}" ")rwcalc_po\";\n"
       "  return text;\n}\n}  // namespace rwcalc\n")
  configure_file(${out}.tmp ${out} COPYONLY)  # rewritten only when it changes
  target_sources(${target} PRIVATE ${out})
  set_source_files_properties(${out} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
endfunction()
