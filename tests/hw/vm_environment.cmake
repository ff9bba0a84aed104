# vm_environment_tests: what the VM promises the other hw tests (root, the modules loaded, the
# device nodes, configfs, loopback, a writable TMPDIR), so that a broken harness fails here
# with a plain message instead of as a puzzling driver test failure.
posefair_add_test(vm_environment_tests
  SOURCES vm_environment_tests.cpp
  LABELS "hw")
