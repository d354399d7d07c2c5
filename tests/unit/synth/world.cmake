# The world, map and release writer (`nsgraph synth`): tests generate the tiny release
# once per binary (synth/<Suite>.<Test>).
nsg_add_test(synth PART world
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/test_world_map.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_world_organic.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_world_organic_features.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_world_release.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_world_changes.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_world_py_json.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_synth_config.cpp
  DEPS nsg::synth nsg::nuscenes nsg::validate nsg::dep::json)
add_dependencies(test_synth_world nsgraph)
# The Python-style JSON writer is internal to the module; its test reaches into src/.
target_include_directories(test_synth_world PRIVATE ${PROJECT_SOURCE_DIR}/lib/synth/src)
