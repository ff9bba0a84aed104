# Reference orientation predictors: the baselines of the quality benchmark's prediction table
# (docs/benchmarks.md).
target_sources(posefair_core PRIVATE src/pose_prediction.cpp)
