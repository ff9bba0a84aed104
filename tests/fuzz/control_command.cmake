# The control socket's request parser (docs/operations.md, "Control socket"), seeded with every
# command (tests/fuzz/corpus/control_command/).
posefair_add_fuzz_target(control_command SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/control_command_fuzz.cpp LIBS posefair::protocol)
