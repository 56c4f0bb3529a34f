# Empty compiler generated dependencies file for test_force_over_life.
# This may be replaced when dependencies are built.
