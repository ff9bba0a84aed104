# GPIO through libgpiod against gpio-sim (root, inside the test VM): edge timestamps and their
# pairing with samples, a busy line taken once released, the output line per pose, and
# posefaird end to end with a serial stream on a pseudo-terminal.
find_package(PkgConfig REQUIRED)
pkg_check_modules(GPIOD_TESTS REQUIRED IMPORTED_TARGET libgpiod)  # the test holds and inspects lines itself
posefair_add_test(gpio_tests
  SOURCES gpio_tests.cpp
  LIBS posefair::protocol posefair::drivers PkgConfig::GPIOD_TESTS
  LABELS "hw;gpio")
add_dependencies(gpio_tests posefaird)
