# Tables, Database, LiDAR/JPEG/PNG/detection readers and `inspect sweep`.
nsg_add_test(nuscenes PART tables
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/test_tables.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_malformed.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_lidar.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_images.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_detections.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_real_table_quirks.cpp
  DEPS nsg::nuscenes nsg::dep::json nsg::dep::turbojpeg nsg::dep::png)
add_dependencies(test_nuscenes_tables nsgraph)
