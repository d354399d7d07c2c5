# Map expansion reader and `inspect centerlines`.
nsg_add_test(nuscenes PART map
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/test_map_expansion.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_map_errors.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_map_cli.cpp
  DEPS nsg::nuscenes nsg::dep::json)
add_dependencies(test_nuscenes_map nsgraph)
