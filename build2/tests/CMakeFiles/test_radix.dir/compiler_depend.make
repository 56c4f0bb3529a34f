# Empty compiler generated dependencies file for test_radix.
# This may be replaced when dependencies are built.
