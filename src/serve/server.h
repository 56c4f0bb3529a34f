/* The HTTP side of `pfx preview`: a libmicrohttpd daemon on a loopback
 * socket answering the routes of serve/routes.c from a live session. It
 * checks every request (Host, token) before any route sees it. */
#ifndef PFX_SERVE_SERVER_H
#define PFX_SERVE_SERVER_H

#include <stdbool.h>

#include "base/diag.h"
#include "jobs/session.h"
#include "serve/compare.h"

typedef struct pfx_server pfx_server;

typedef struct pfx_server_options {
    const char *host; /* the numeric address to bind: 127.0.0.1 unless --host */
    unsigned port;    /* 0: any free one */
    pfx_session *session;
} pfx_server_options;

/* Binds, listens and starts serving. The token (32 hex digits from the
 * kernel's random bytes) is made here. NULL, with a one-line reason in d,
 * when the address cannot be bound (in use, not local) or the daemon
 * cannot start. Stop with pfx_server_stop. */
pfx_server *pfx_server_start(const pfx_server_options *o, pfx_diags *d);
/* The session the routes answer from; set before the token is shown. */
void pfx_server_set_session(pfx_server *s, pfx_session *session);
/* The comparison the routes answer `variant=compare` from (the caller's,
 * freed after pfx_server_stop). */
void pfx_server_set_compare(pfx_server *s, pfx_compare *compare);
/* The port bound (the one picked when 0 was asked for). */
unsigned pfx_server_port(const pfx_server *s);
/* The token every request must carry; owned by s. */
const char *pfx_server_token(const pfx_server *s);
/* Ends open event streams, stops the daemon and joins its threads, frees
 * s. The session is the caller's; stop it first so waits return. NULL:
 * no-op. */
void pfx_server_stop(pfx_server *s);

#endif
