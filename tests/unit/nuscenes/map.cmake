# Map expansion reader and `inspect centerlines`.
nsg_add_test(nuscenes PART map
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/test_map_expansion.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_map_errors.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_map_cli.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_real_map_defects.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_real_defects_generate.cpp
  DEPS nsg::nuscenes nsg::graph nsg::dep::json)
add_dependencies(test_nuscenes_map nsgraph)
