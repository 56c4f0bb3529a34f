/* The seam between render.c and the code that makes a GL context. A backend
 * (gl_osmesa.c, gl_egl.c) makes an OpenGL 3.3 core-profile context with no
 * window and no default framebuffer worth drawing to, and hands back how to
 * make it current and how to find GL entry points. render.c knows nothing
 * else about it: it draws into its own framebuffer object either way. */
#ifndef PFX_GL_CONTEXT_H
#define PFX_GL_CONTEXT_H

#include <stdbool.h>
#include <stddef.h>

#include "base/diag.h"

/* Any GL entry point, to be cast to its real type (the generic function
 * pointer type, so the cast is well defined and GCC does not warn). */
typedef void (*pfx_gl_proc)(void);

/* A context and its operations. A backend puts this first in its own
 * struct, so the pointers receive the whole object. */
typedef struct pfx_gl_context pfx_gl_context;
struct pfx_gl_context {
    /* The renderer's name as --renderer spells it ("osmesa", "egl-cpu",
     * "egl-gpu"), for messages and reports; a static string. */
    const char *name;
    /* Makes the context current in the calling thread; cheap when it
     * already is. Returns false when the library refuses. */
    bool (*make_current)(pfx_gl_context *c);
    /* Any GL function by name ("glClear", "glDrawArraysInstanced"), 1.0
     * ones included, or NULL when there is none. Valid while the context
     * lives and is current. */
    pfx_gl_proc (*get_proc_address)(const char *name);
    /* Unbinds the context if it is current, then frees it and every GL
     * object it owns. */
    void (*destroy)(pfx_gl_context *c);
};

/* OSMesa (Mesa's llvmpipe through libOSMesa, gone from Mesa 25.1). Returns a
 * current context the caller destroys through ->destroy, or NULL with a
 * one-line error in d. Defined only when pfx is built with OSMesa. */
pfx_gl_context *pfx_gl_osmesa_create(pfx_diags *d);

/* EGL with no window system: with gpu false Mesa's software device
 * (llvmpipe), with gpu true the first hardware EGL device. Returns a
 * current context the caller destroys through ->destroy, or NULL with a
 * one-line error in d naming what is missing. Defined only when pfx is
 * built with EGL. */
pfx_gl_context *pfx_gl_egl_create(bool gpu, pfx_diags *d);

#endif
