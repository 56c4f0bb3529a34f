# Empty compiler generated dependencies file for test_stability.
# This may be replaced when dependencies are built.
