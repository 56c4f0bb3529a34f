# Empty compiler generated dependencies file for test_collide.
# This may be replaced when dependencies are built.
