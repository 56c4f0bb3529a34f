# Empty dependencies file for pfxcore.
# This may be replaced when dependencies are built.
