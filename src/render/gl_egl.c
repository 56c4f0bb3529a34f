/* The EGL backend: an OpenGL 3.3 core context on an EGL display with no
 * window system and no surface. egl-cpu takes Mesa's software device
 * (llvmpipe), egl-gpu the first hardware device. It goes through glvnd's
 * libEGL, needs neither X11 nor a /dev/dri node, makes the context and
 * finds entry points; it draws nothing. */
#define EGL_NO_X11 /* eglplatform.h: plain integer types, no X11 headers */
#include "render/gl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct egl_context {
    pfx_gl_context base; /* first, so a pfx_gl_context * is one of these */
    EGLDisplay display;
    EGLContext ctx;
} egl_context;

/* Whether the space-separated extension list names `want` as a whole word
 * (EGL_EXT_device_base must not match EGL_EXT_device_base_foo). */
static bool has_ext(const char *list, const char *want) {
    size_t n = strlen(want);
    for (const char *p = list; p && (p = strstr(p, want)) != NULL; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == 0))
            return true;
    return false;
}

static bool egl_make_current(pfx_gl_context *c) {
    egl_context *e = (egl_context *)c;
    /* The bound API is per thread, and a thread that never bound one would
     * look for an OpenGL ES context. */
    if (eglQueryAPI() != EGL_OPENGL_API && !eglBindAPI(EGL_OPENGL_API))
        return false;
    if (eglGetCurrentContext() == e->ctx)
        return true;
    return eglMakeCurrent(e->display, EGL_NO_SURFACE, EGL_NO_SURFACE, e->ctx);
}

/* With glvnd, eglGetProcAddress answers for every GL function, 1.0 ones
 * included (EGL_KHR_client_get_all_proc_addresses); the stubs dispatch to
 * whichever vendor owns the current context. */
static pfx_gl_proc egl_get_proc_address(const char *name) {
    return (pfx_gl_proc)eglGetProcAddress(name);
}

/* The display is not terminated: eglGetPlatformDisplayEXT hands every
 * caller the same display for the same device, and eglTerminate is not
 * reference counted, so terminating it would pull it from under another
 * renderer. libEGL releases it at exit. */
static void egl_destroy(pfx_gl_context *c) {
    egl_context *e = (egl_context *)c;
    if (!e)
        return;
    if (e->ctx != EGL_NO_CONTEXT) {
        if (eglQueryAPI() == EGL_OPENGL_API && eglGetCurrentContext() == e->ctx)
            eglMakeCurrent(e->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(e->display, e->ctx);
    }
    free(e);
}

/* How the display was found: a device chosen by its extensions is what was
 * asked for; the surfaceless platform is whatever Mesa picks, so egl-cpu
 * checks the renderer string once the context is current. */
typedef enum display_source { FROM_DEVICE, FROM_SURFACELESS } display_source;

/* The display of the first EGL device that is (gpu false) or is not (gpu
 * true) Mesa's software device, or for egl-cpu without device listing the
 * surfaceless platform. The extension functions come through
 * eglGetProcAddress: glvnd's libEGL does not export them. Returns
 * EGL_NO_DISPLAY with a message. */
static EGLDisplay open_display(bool gpu, const char *name, display_source *source, pfx_diags *d) {
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!has_ext(client, "EGL_EXT_platform_base") || !get_platform_display) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "renderer '%s': libEGL lacks EGL_EXT_platform_base", name);
        return EGL_NO_DISPLAY;
    }
    PFNEGLQUERYDEVICESEXTPROC query_devices =
        (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    PFNEGLQUERYDEVICESTRINGEXTPROC query_device_string =
        (PFNEGLQUERYDEVICESTRINGEXTPROC)eglGetProcAddress("eglQueryDeviceStringEXT");
    bool listing =
        (has_ext(client, "EGL_EXT_device_base") || (has_ext(client, "EGL_EXT_device_enumeration") &&
                                                    has_ext(client, "EGL_EXT_device_query"))) &&
        has_ext(client, "EGL_EXT_platform_device") && query_devices && query_device_string;
    EGLint count = 0;
    if (listing && query_devices(0, NULL, &count) && count > 0) {
        EGLDeviceEXT *devices = malloc((size_t)count * sizeof *devices);
        if (!devices) {
            pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY,
                           "renderer '%s': out of memory listing EGL devices", name);
            return EGL_NO_DISPLAY;
        }
        EGLDisplay display = EGL_NO_DISPLAY;
        if (query_devices(count, devices, &count))
            for (EGLint i = 0; i < count && display == EGL_NO_DISPLAY; i++) {
                const char *ext = query_device_string(devices[i], EGL_EXTENSIONS);
                if (has_ext(ext, "EGL_MESA_device_software") != gpu)
                    display = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL);
            }
        free(devices);
        if (display != EGL_NO_DISPLAY) {
            *source = FROM_DEVICE;
            return display;
        }
    }
    if (gpu) {
        if (listing)
            pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                           "renderer '%s': no GPU EGL device (eglQueryDevicesEXT lists %d, none of "
                           "them hardware)",
                           name, (int)count);
        else
            pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                           "renderer '%s': libEGL cannot list devices (needs EGL_EXT_device_base "
                           "and EGL_EXT_platform_device)",
                           name);
        return EGL_NO_DISPLAY;
    }
    if (!has_ext(client, "EGL_MESA_platform_surfaceless")) {
        pfx_diag_error(
            d, PFX_RULE_RENDERER_FAILED,
            "renderer '%s': no Mesa software EGL device (EGL_MESA_device_software) and no "
            "EGL_MESA_platform_surfaceless",
            name);
        return EGL_NO_DISPLAY;
    }
    *source = FROM_SURFACELESS;
    EGLDisplay display =
        get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (display == EGL_NO_DISPLAY)
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "renderer '%s': no surfaceless EGL display (EGL error 0x%04x)", name,
                       (unsigned)eglGetError());
    return display;
}

/* Whether the current context renders in software: Mesa's CPU rasterisers
 * name themselves in GL_RENDERER. */
static bool renders_in_software(char *renderer, size_t size) {
    typedef const unsigned char *(*get_string_fn)(unsigned int);
    get_string_fn get_string = (get_string_fn)eglGetProcAddress("glGetString");
    const unsigned char *s = get_string ? get_string(0x1F01 /* GL_RENDERER */) : NULL;
    snprintf(renderer, size, "%s", s ? (const char *)s : "unknown");
    return strstr(renderer, "llvmpipe") || strstr(renderer, "softpipe");
}

/* Initialises the display and makes a current 3.3 core context on it with
 * no surface. Returns false with a message naming the missing piece. */
static bool make_context(egl_context *e, pfx_diags *d) {
    const char *name = e->base.name;
    EGLint major = 0, minor = 0;
    if (!eglInitialize(e->display, &major, &minor)) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "renderer '%s': eglInitialize failed (EGL error 0x%04x)", name,
                       (unsigned)eglGetError());
        return false;
    }
    const char *ext = eglQueryString(e->display, EGL_EXTENSIONS);
    static const char *const needed[] = {"EGL_KHR_create_context", "EGL_KHR_surfaceless_context"};
    for (size_t i = 0; i < sizeof needed / sizeof *needed; i++)
        if (!has_ext(ext, needed[i])) {
            pfx_diag_error(d, PFX_RULE_RENDERER_FAILED, "renderer '%s': the EGL display lacks %s",
                           name, needed[i]);
            return false;
        }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "renderer '%s': the EGL display has no desktop OpenGL", name);
        return false;
    }
    /* Without EGL_KHR_no_config_context, any config that renders OpenGL:
     * there is no surface, so its buffers never matter. */
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!has_ext(ext, "EGL_KHR_no_config_context") &&
        !has_ext(ext, "EGL_MESA_configless_context")) {
        const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLint n = 0;
        if (!eglChooseConfig(e->display, want, &config, 1, &n) || n < 1) {
            pfx_diag_error(
                d, PFX_RULE_RENDERER_FAILED,
                "renderer '%s': the EGL display lacks EGL_KHR_no_config_context and has no "
                "OpenGL config",
                name);
            return false;
        }
    }
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION_KHR,
                              3,
                              EGL_CONTEXT_MINOR_VERSION_KHR,
                              3,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK_KHR,
                              EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT_KHR,
                              EGL_NONE};
    e->ctx = eglCreateContext(e->display, config, EGL_NO_CONTEXT, attribs);
    if (e->ctx == EGL_NO_CONTEXT) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "renderer '%s': cannot create an OpenGL 3.3 core profile context (EGL error "
                       "0x%04x)",
                       name, (unsigned)eglGetError());
        return false;
    }
    if (!eglMakeCurrent(e->display, EGL_NO_SURFACE, EGL_NO_SURFACE, e->ctx)) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "renderer '%s': cannot make the EGL context current (EGL error "
                       "0x%04x)",
                       name, (unsigned)eglGetError());
        return false;
    }
    return true;
}

pfx_gl_context *pfx_gl_egl_create(bool gpu, pfx_diags *d) {
    egl_context *e = calloc(1, sizeof *e);
    if (!e) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for an EGL context");
        return NULL;
    }
    e->base = (pfx_gl_context){.name = gpu ? "egl-gpu" : "egl-cpu",
                               .make_current = egl_make_current,
                               .get_proc_address = egl_get_proc_address,
                               .destroy = egl_destroy};
    e->ctx = EGL_NO_CONTEXT;
    display_source source = FROM_DEVICE;
    e->display = open_display(gpu, e->base.name, &source, d);
    if (e->display == EGL_NO_DISPLAY || !make_context(e, d)) {
        egl_destroy(&e->base);
        return NULL;
    }
    char renderer[256];
    if (source == FROM_SURFACELESS && !renders_in_software(renderer, sizeof renderer)) {
        pfx_diag_error(d, PFX_RULE_RENDERER_FAILED,
                       "renderer '%s': no Mesa software EGL device, and the surfaceless display "
                       "renders on '%s'",
                       e->base.name, renderer);
        egl_destroy(&e->base);
        return NULL;
    }
    return &e->base;
}
