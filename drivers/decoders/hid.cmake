# USB HID: the HID decoder registry, the report descriptor parser, the HID Sensor orientation decoder ("hid-sensor"), the
# vendor report layout decoder ("hid-vendor"); and the GPIO data-ready edge pairing rule that
# the GPIO line driver applies to any stream's samples. All pure (no I/O), host-testable.
target_sources(posefair_drivers PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/src/hid_decoder_registry.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/hid_report_descriptor.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/hid_sensor_orientation_decoder.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/hid_vendor_layout_decoder.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/gpio_edge_pairing.cpp)
