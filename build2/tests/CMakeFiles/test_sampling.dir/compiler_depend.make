# Empty compiler generated dependencies file for test_sampling.
# This may be replaced when dependencies are built.
