/* The routes of the preview server, one row each (method, path, handler),
 * and the page's embedded files. server.c checks Host and token first. */
#ifndef PFX_SERVE_ROUTES_H
#define PFX_SERVE_ROUTES_H

#include <microhttpd.h>
#include <stdatomic.h>
#include <stdbool.h>

#include "jobs/session.h"
#include "serve/compare.h"

/* What a handler may use: the session, and the flag that ends streams. */
typedef struct pfx_route_ctx {
    pfx_session *session;
    pfx_compare *compare; /* A/B against another file or seed; NULL: none can be set */
    atomic_bool *stopping;
    /* The page's Set-Cookie: the token, for requests that do not carry
     * it in the query (the page's script and style sheet). */
    const char *set_cookie;
} pfx_route_ctx;

/* Answers one request (url is the path without the query); returns what
 * MHD_queue_response returned. */
typedef enum MHD_Result (*pfx_route_fn)(const pfx_route_ctx *c, struct MHD_Connection *conn,
                                        const char *url);

/* The handler for method and path, or NULL when no row matches (a 404). */
pfx_route_fn pfx_route_find(const char *method, const char *url);

/* Queues a small text response with the given status and content type. */
enum MHD_Result pfx_route_text(struct MHD_Connection *conn, unsigned status, const char *type,
                               const char *text);

#endif
