# Sensor simulators and image encoders (brief H5); CTest names synth/<Suite>.<Test>.
nsg_add_test(synth PART sensors
  SOURCES
    test_sensors_lidar.cpp
    test_sensors_camera.cpp
    test_sensors_encode.cpp
  DEPS nsg::synth nsg::dep::json nsg::dep::turbojpeg nsg::dep::png)
