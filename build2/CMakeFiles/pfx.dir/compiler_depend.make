# Empty compiler generated dependencies file for pfx.
# This may be replaced when dependencies are built.
