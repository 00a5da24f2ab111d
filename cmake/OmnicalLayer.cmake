# omnical_layer(<layer> <sources...>): the library target of one layer (docs/layers.md):
# omnical_<layer>, its alias and export name omnical::<layer>, headers included as
# "<folder>/<file>.h" from the source root (installed under include/omnical/).
function(omnical_layer layer)
  add_library(omnical_${layer} ${ARGN})
  add_library(omnical::${layer} ALIAS omnical_${layer})
  set_target_properties(omnical_${layer} PROPERTIES EXPORT_NAME ${layer} OUTPUT_NAME omnical_${layer})
  target_include_directories(omnical_${layer} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/omnical>)
endfunction()
