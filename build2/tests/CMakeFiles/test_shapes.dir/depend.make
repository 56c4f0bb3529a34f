# Empty dependencies file for test_shapes.
# This may be replaced when dependencies are built.
