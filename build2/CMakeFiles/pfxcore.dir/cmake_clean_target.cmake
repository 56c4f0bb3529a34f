file(REMOVE_RECURSE
  "libpfxcore.a"
)
