# Empty compiler generated dependencies file for test_kill.
# This may be replaced when dependencies are built.
