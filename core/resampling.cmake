# Live use of the geometric splines: gap bridging before the fairing window and output-rate
# resampling after it (docs/splines.md, "In the daemon").
target_sources(posefair_core PRIVATE src/gap_bridge.cpp src/fixed_rate_resampler.cpp src/rigid_pose_lerp.cpp)
