# Empty compiler generated dependencies file for test_diag_rules.
# This may be replaced when dependencies are built.
