# The config parser, seeded with the example configs (config/) and the demo's.
posefair_add_fuzz_target(config SOURCE config_fuzz.cpp LIBS posefair::config
                         CORPUS ${PROJECT_SOURCE_DIR}/config ${PROJECT_SOURCE_DIR}/data/demo)
