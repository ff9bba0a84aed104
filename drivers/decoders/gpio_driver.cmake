# GPIO lines through libgpiod 1.6 (Debian 12: libgpiod-dev): the data-ready input line that
# pairs a stream's samples with its edges' kernel timestamps (gpio_edge_pairing.cpp, pure, is
# in hid.cmake), and the output line toggled per published pose or as a heartbeat.
pkg_check_modules(GPIOD REQUIRED IMPORTED_TARGET libgpiod)
target_sources(posefair_drivers PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/src/gpio_data_ready.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/gpio_output_line.cpp)
target_link_libraries(posefair_drivers PRIVATE PkgConfig::GPIOD)
