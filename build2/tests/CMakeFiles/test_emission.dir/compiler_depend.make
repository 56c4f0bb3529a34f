# Empty compiler generated dependencies file for test_emission.
# This may be replaced when dependencies are built.
