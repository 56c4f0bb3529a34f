/* The OSMesa backend: a core-profile 3.3 context from libOSMesa (Mesa's
 * llvmpipe behind the old off-screen API, removed in Mesa 25.1). It makes
 * the context and finds entry points; it draws nothing. */
#include "render/gl_context.h"

#include <GL/osmesa.h>

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct osmesa_context {
    pfx_gl_context base; /* first, so a pfx_gl_context * is one of these */
    OSMesaContext ctx;
    /* OSMesa insists on a colour buffer to be made current; every draw goes
     * to render.c's framebuffer object, so one pixel is enough. */
    unsigned char buffer[4];
} osmesa_context;

static bool osmesa_make_current(pfx_gl_context *c) {
    osmesa_context *o = (osmesa_context *)c;
    if (OSMesaGetCurrentContext() == o->ctx)
        return true;
    return OSMesaMakeCurrent(o->ctx, o->buffer, GL_UNSIGNED_BYTE, 1, 1);
}

/* OSMesaGetProcAddress finds every GL function, 1.0 ones included (Mesa's
 * dispatch stubs), whether or not this libOSMesa also exports it. */
static pfx_gl_proc osmesa_get_proc_address(const char *name) {
    return (pfx_gl_proc)OSMesaGetProcAddress(name);
}

static void osmesa_destroy(pfx_gl_context *c) {
    osmesa_context *o = (osmesa_context *)c;
    if (!o)
        return;
    if (o->ctx) {
        /* Unbind first so the thread is not left with a dangling context. */
        if (OSMesaGetCurrentContext() == o->ctx)
            OSMesaMakeCurrent(NULL, NULL, 0, 0, 0);
        OSMesaDestroyContext(o->ctx);
    }
    free(o);
}

pfx_gl_context *pfx_gl_osmesa_create(pfx_diags *d) {
    osmesa_context *o = calloc(1, sizeof *o);
    if (!o) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for an OSMesa context");
        return NULL;
    }
    o->base = (pfx_gl_context){.name = "osmesa",
                               .make_current = osmesa_make_current,
                               .get_proc_address = osmesa_get_proc_address,
                               .destroy = osmesa_destroy};
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           0,
                           OSMESA_STENCIL_BITS,
                           0,
                           OSMESA_ACCUM_BITS,
                           0,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           3,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           3,
                           0};
    o->ctx = OSMesaCreateContextAttribs(attribs, NULL);
    if (!o->ctx) {
        pfx_diag_error(
            d, PFX_RULE_RENDERER_FAILED,
            "renderer 'osmesa': cannot create an OSMesa OpenGL 3.3 core profile context");
        osmesa_destroy(&o->base);
        return NULL;
    }
    if (!osmesa_make_current(&o->base)) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "renderer 'osmesa': cannot make the OSMesa context current");
        osmesa_destroy(&o->base);
        return NULL;
    }
    return &o->base;
}
