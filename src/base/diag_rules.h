/* The rules: every kind of problem pfx reports, one row each. A rule is a
 * kind of problem ("out-of-range"), not a call site: many messages share one.
 * Its id (PFX + the number) is printed after each diagnostic, in the JSON
 * lines, in SARIF and in man/pfx.1, so CI filters and suppressions can
 * name it.
 *
 * NEVER renumber or reuse a row's number once it is given: ids are a
 * published interface. A rule that goes out of use keeps its row (mark its
 * help "(retired)"); a new one takes the next free number in its range.
 *
 * Ranges: 1xxx syntax and parse, 2xxx keys and types, 3xxx values and
 * ranges, 4xxx references (names, files), 5xxx stability and physics
 * warnings, 6xxx resource bounds, 9xxx runtime and I/O failures.
 *
 * X(number, IDENT, "kebab-name", default severity, "one-line help") */
#ifndef PFX_DIAG_RULES_H
#define PFX_DIAG_RULES_H

#define PFX_DIAG_RULES(X)                                                                          \
    /* 1xxx syntax and parse */                                                                    \
    X(1001, YAML_SYNTAX, "yaml-syntax", ERROR,                                                     \
      "The file is not well-formed YAML (libyaml's own error: indentation, a tab, an unclosed "    \
      "bracket).")                                                                                 \
    X(1002, NOT_UTF8, "not-utf8", ERROR,                                                           \
      "The file is not UTF-8 text (a malformed byte, a NUL byte).")                                \
    X(1003, MULTIPLE_DOCUMENTS, "multiple-documents", ERROR,                                       \
      "The file holds more than one YAML document.")                                               \
    X(1004, UNKNOWN_ANCHOR, "unknown-anchor", ERROR,                                               \
      "A YAML alias names an anchor not defined before it.")                                       \
    X(1005, COMPLEX_KEY, "complex-key", ERROR,                                                     \
      "A mapping key is a list or a mapping, not a name.")                                         \
    X(1006, EMPTY_FILE, "empty-file", ERROR, "The file holds no effect.")                          \
    X(1007, FORMAT_VERSION, "format-version", ERROR,                                               \
      "The 'pfx' format version is missing or names a version this pfx does not read.")            \
    /* 2xxx keys and types */                                                                      \
    X(2001, UNKNOWN_KEY, "unknown-key", ERROR,                                                     \
      "A key pfx does not know in its mapping (a misspelling gets a suggestion).")                 \
    X(2002, DUPLICATE_KEY, "duplicate-key", ERROR, "A mapping gives the same key twice.")          \
    X(2003, WRONG_TYPE, "wrong-type", ERROR,                                                       \
      "A value has the wrong type: a list where a number belongs, text where a mapping does.")     \
    X(2004, MISSING_KEY, "missing-key", ERROR,                                                     \
      "A required key is absent (a shape's 'radius', a force's 'type', a spawn's 'emit').")        \
    X(2005, CONFLICTING_KEYS, "conflicting-keys", ERROR,                                           \
      "Two keys that exclude each other are both given ('rate' and 'interval').")                  \
    X(2006, INAPPLICABLE_KEY, "inapplicable-key", ERROR,                                           \
      "A key does not apply where it is written ('axis' without align: axis).")                    \
    /* 3xxx values and ranges */                                                                   \
    X(3001, OUT_OF_RANGE, "out-of-range", ERROR,                                                   \
      "A number lies outside its allowed range, or is not finite.")                                \
    X(3002, NOT_INTEGER, "not-integer", ERROR, "A count or a number of cycles is not whole.")      \
    X(3003, MALFORMED_VALUE, "malformed-value", ERROR,                                             \
      "A value's text does not parse (a colour '#12345', a number '1.2.3').")                      \
    X(3004, INVERTED_RANGE, "inverted-range", ERROR,                                               \
      "A [min, max] range or a clamp has its minimum above its maximum.")                          \
    X(3005, ZERO_VECTOR, "zero-vector", ERROR, "A direction, axis or normal is the zero vector.")  \
    X(3006, OUT_OF_ORDER, "out-of-order", ERROR,                                                   \
      "Keys, bursts or gradient stops are not in increasing order.")                               \
    X(3007, INCONSISTENT_VALUES, "inconsistent-values", ERROR,                                     \
      "Values valid one by one contradict each other (a flipbook grid with too few cells).")       \
    X(3008, UNKNOWN_CHOICE, "unknown-choice", ERROR,                                               \
      "A word is not one of those a key accepts (blend 'addd', a force type 'vortx').")            \
    /* 4xxx references */                                                                          \
    X(4001, UNKNOWN_NAME, "unknown-name", ERROR,                                                   \
      "A name refers to an emitter, force or deflector the effect does not define.")               \
    X(4002, MISSING_FILE, "missing-file", ERROR,                                                   \
      "A file cannot be opened (the effect, a texture, a mesh).")                                  \
    X(4003, INVALID_FILE, "invalid-file", ERROR,                                                   \
      "A file the effect names is not what it should be (not a PNG, a malformed OBJ).")            \
    X(4004, REFERENCE_CYCLE, "reference-cycle", ERROR,                                             \
      "Emitters spawn each other in a cycle, or a ribbon trails itself.")                          \
    X(4005, INVALID_REFERENCE, "invalid-reference", ERROR,                                         \
      "A reference joins emitters that cannot work together (a ribbon fed by no trail, or two).")  \
    /* 5xxx stability and physics */                                                               \
    X(5001, UNSTABLE_INTEGRATOR, "unstable-integrator", WARNING,                                   \
      "The integrator is unstable or inaccurate for an emitter's forces at the simulation rate.")  \
    X(5002, LOOP_SEAM, "loop-seam", WARNING,                                                       \
      "A looping effect will show a seam or will not repeat exactly.")                             \
    X(5003, DIES_AT_BIRTH, "dies-at-birth", WARNING,                                               \
      "Every particle is killed in its first step.")                                               \
    X(5004, INEFFECTIVE_SETTING, "ineffective-setting", WARNING,                                   \
      "A setting has no effect as written (a normal map on an unlit emitter).")                    \
    X(5005, EMPTY_EFFECT, "empty-effect", WARNING,                                                 \
      "The effect has no emitters: every frame is empty.")                                         \
    /* 6xxx resource bounds */                                                                     \
    X(6001, TOO_MANY, "too-many", ERROR,                                                           \
      "A list is longer than pfx allows (emitters, forces, bursts, gradient stops, sprites).")     \
    X(6002, TOO_LARGE, "too-large", ERROR,                                                         \
      "An input exceeds a size bound (a file, nesting, alias expansion, a texture, an image).")    \
    X(6003, TOO_MUCH_WORK, "too-much-work", ERROR,                                                 \
      "The frame or simulation step count exceeds pfx's bound.")                                   \
    X(6004, POOL_SATURATED, "pool-saturated", WARNING,                                             \
      "An emitter needs more live particles than its share of the particle budget.")               \
    X(6005, MEMORY_BOUND, "memory-bound", WARNING,                                                 \
      "A render needs more memory than the bound (--max-memory).")                                 \
    X(6006, HEAVY_SIMULATION, "heavy-simulation", WARNING,                                         \
      "The simulation would take hours or more (particle-steps over the warning bound).")          \
    /* 9xxx runtime and I/O failures */                                                            \
    X(9001, OUT_OF_MEMORY, "out-of-memory", ERROR, "An allocation failed.")                        \
    X(9002, READ_FAILED, "read-failed", ERROR, "A file or directory could not be read.")           \
    X(9003, WRITE_FAILED, "write-failed", ERROR,                                                   \
      "An output could not be written, created, synced or removed.")                               \
    X(9004, RENDERER_FAILED, "renderer-failed", ERROR,                                             \
      "The renderer could not start or draw (no GL context, a shader, an OpenGL error).")          \
    X(9005, SIMULATION_DIVERGED, "simulation-diverged", ERROR,                                     \
      "A particle became non-finite or ran away during the simulation.")                           \
    X(9006, INCONSISTENT_SLICES, "inconsistent-slices", ERROR,                                     \
      "Slice manifests or frames do not fit together (a slice missing, a hash mismatch, a name "   \
      "outside the slice's folder, a bad fps).")                                                   \
    X(9007, ENCODE_FAILED, "encode-failed", ERROR,                                                 \
      "An image or video encoder (PNG, WebP, EXR, ffmpeg) failed.")                                \
    X(9008, IMPOSSIBLE_REQUEST, "impossible-request", ERROR,                                       \
      "The command asks for what cannot be made (an atlas grid too small for its frames).")        \
    X(9009, MISSING_TOOL, "missing-tool", ERROR,                                                   \
      "An external program pfx runs (ffmpeg for an MP4 preview) is not on the PATH.")

#endif
