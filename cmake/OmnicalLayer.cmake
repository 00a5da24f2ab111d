# omnical_layer(<layer> <sources...>): the library target of one layer (docs/layers.md):
# omnical_<layer>, its alias and export name omnical::<layer>, headers included as
# "<folder>/<file>.h" from the source root (installed under include/omnical/).
function(omnical_layer layer)
  add_library(omnical_${layer} ${ARGN})
  add_library(omnical::${layer} ALIAS omnical_${layer})
  set_target_properties(omnical_${layer} PROPERTIES EXPORT_NAME ${layer} OUTPUT_NAME omnical_${layer})
  # Unity sources, two per layer for the CI's two cores: every file includes the same heavy
  # headers (Eigen, Ceres, the sensor models), whose parsing and code generation were most
  # of the build. Names in a file's anonymous namespace must therefore differ from those of
  # its layer's other files.
  list(LENGTH ARGN source_count)
  math(EXPR batch "(${source_count} + 1) / 2")
  set_target_properties(omnical_${layer} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${batch})
  target_include_directories(omnical_${layer} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/omnical>)
endfunction()
