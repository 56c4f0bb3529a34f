/* The preview server: a loopback socket (or --host's address) handed to
 * libmicrohttpd, a thread per connection (an event stream and a frame
 * still rendering each block one), and the checks every request passes
 * before its route: the Host header names this server (no DNS
 * rebinding), the token is given (query or cookie). Routes: routes.c. */
#include "serve/server.h"

#include <arpa/inet.h>
#include <errno.h>
#include <microhttpd.h>
#include <netdb.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/socket.h>
#include <unistd.h>

#include "serve/routes.h"

struct pfx_server {
    struct MHD_Daemon *daemon;
    int fd;
    unsigned port;
    char host[64];   /* as bound, for the Host check: "127.0.0.1", "[::1]" */
    char token[33];  /* 32 hex digits */
    char cookie[48]; /* the cookie's name: pfx_token_PORT (one per server on a host) */
    char set_cookie[160];
    atomic_bool stopping;
    pfx_route_ctx ctx;
};

/* Connections at once (the page holds two or three) and bytes a request
 * may use for its headers: a browser's fit easily, a flood does not. */
#define MAX_CONNECTIONS 32
#define REQUEST_MEMORY (32 * 1024)

static bool make_token(char out[33]) {
    unsigned char raw[16];
    size_t got = 0;
    while (got < sizeof raw) {
        ssize_t n = getrandom(raw + got, sizeof raw - got, 0);
        if (n < 0 && errno != EINTR)
            return false;
        got += n > 0 ? (size_t)n : 0;
    }
    for (size_t i = 0; i < sizeof raw; i++)
        snprintf(out + 2 * i, 3, "%02x", raw[i]);
    return true;
}

/* Equal strings, in time that does not depend on where they differ. */
static bool same_secret(const char *a, const char *b) {
    size_t n = strlen(b);
    if (!a || strlen(a) != n)
        return false;
    unsigned char diff = 0;
    for (size_t i = 0; i < n; i++)
        diff |= (unsigned char)(a[i] ^ b[i]);
    return diff == 0;
}

/* The Host header names this server: 127.0.0.1, localhost or [::1] (or
 * the --host address) with the port. Anything else is a page elsewhere
 * reaching loopback through a rebound DNS name. */
static bool host_ok(const pfx_server *s, const char *host) {
    if (!host)
        return false;
    const char *names[] = {"127.0.0.1", "localhost", "[::1]", s->host};
    char want[128];
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        snprintf(want, sizeof want, "%s:%u", names[i], s->port);
        if (!strcmp(host, want))
            return true;
    }
    return false;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *conn, const char *url,
                                  const char *method, const char *version, const char *upload,
                                  size_t *upload_size, void **state) {
    (void)version;
    (void)upload;
    (void)upload_size;
    (void)state;
    pfx_server *s = cls;
    /* Answered on the first call, from the headers alone: no route takes
     * a body, so one announced is refused before it is read. */
    const char *length = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Content-Length");
    if ((length && strcmp(length, "0")) ||
        MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Transfer-Encoding"))
        return pfx_route_text(conn, MHD_HTTP_CONTENT_TOO_LARGE, "text/plain", "no bodies\n");
    if (!host_ok(s, MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Host")))
        return pfx_route_text(conn, MHD_HTTP_FORBIDDEN, "text/plain", "pfx: foreign Host\n");
    const char *token = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "token");
    if (!token)
        token = MHD_lookup_connection_value(conn, MHD_COOKIE_KIND, s->cookie);
    if (!same_secret(token, s->token))
        return pfx_route_text(conn, MHD_HTTP_FORBIDDEN, "text/plain",
                              "pfx: open the URL pfx preview printed, with its token\n");
    pfx_route_fn fn = pfx_route_find(method, url);
    if (!fn)
        return pfx_route_text(conn, MHD_HTTP_NOT_FOUND, "text/plain", "pfx: no such page\n");
    return fn(&s->ctx, conn, url);
}

/* A socket bound to host:port and listening, or -1 with the reason in d. */
static int listen_on(const char *host, unsigned port, pfx_diags *d) {
    struct addrinfo hints = {.ai_socktype = SOCK_STREAM,
                             .ai_flags = AI_NUMERICHOST | AI_NUMERICSERV | AI_PASSIVE};
    struct addrinfo *ai = NULL;
    char service[16];
    snprintf(service, sizeof service, "%u", port);
    int rc = getaddrinfo(host, service, &hints, &ai);
    if (rc) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED,
                       "cannot listen on '%s': not a numeric IPv4 or IPv6 address", host);
        return -1;
    }
    int fd = socket(ai->ai_family, SOCK_STREAM | SOCK_CLOEXEC, 0);
    int one = 1;
    if (fd >= 0)
        setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (fd < 0 || bind(fd, ai->ai_addr, ai->ai_addrlen) || listen(fd, 16)) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot listen on %s%s%s:%u: %s",
                       ai->ai_family == AF_INET6 ? "[" : "", host,
                       ai->ai_family == AF_INET6 ? "]" : "", port, strerror(errno));
        if (fd >= 0)
            close(fd);
        fd = -1;
    }
    freeaddrinfo(ai);
    return fd;
}

pfx_server *pfx_server_start(const pfx_server_options *o, pfx_diags *d) {
    pfx_server *s = calloc(1, sizeof *s);
    if (!s || !make_token(s->token)) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "cannot make the server's token");
        free(s);
        return NULL;
    }
    s->fd = listen_on(o->host, o->port, d);
    if (s->fd < 0) {
        free(s);
        return NULL;
    }
    struct sockaddr_storage sa;
    socklen_t len = sizeof sa;
    getsockname(s->fd, (struct sockaddr *)&sa, &len);
    s->port = ntohs(sa.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&sa)->sin6_port
                                             : ((struct sockaddr_in *)&sa)->sin_port);
    snprintf(s->host, sizeof s->host, sa.ss_family == AF_INET6 ? "[%s]" : "%s", o->host);
    snprintf(s->cookie, sizeof s->cookie, "pfx_token_%u", s->port);
    snprintf(s->set_cookie, sizeof s->set_cookie, "%s=%s; Path=/; HttpOnly; SameSite=Strict",
             s->cookie, s->token);
    s->ctx.set_cookie = s->set_cookie;
    s->ctx.session = o->session;
    s->ctx.stopping = &s->stopping;
    s->daemon = MHD_start_daemon(
        MHD_USE_THREAD_PER_CONNECTION | MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_POLL, 0, NULL,
        NULL, on_request, s, MHD_OPTION_LISTEN_SOCKET, s->fd, MHD_OPTION_CONNECTION_LIMIT,
        (unsigned)MAX_CONNECTIONS, MHD_OPTION_CONNECTION_MEMORY_LIMIT, (size_t)REQUEST_MEMORY,
        MHD_OPTION_CONNECTION_TIMEOUT, 120u, MHD_OPTION_END);
    if (!s->daemon) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot start the HTTP server on port %u", s->port);
        close(s->fd);
        free(s);
        return NULL;
    }
    return s;
}

void pfx_server_set_session(pfx_server *s, pfx_session *session) { s->ctx.session = session; }
void pfx_server_set_compare(pfx_server *s, pfx_compare *compare) { s->ctx.compare = compare; }

unsigned pfx_server_port(const pfx_server *s) { return s->port; }
const char *pfx_server_token(const pfx_server *s) { return s->token; }

void pfx_server_stop(pfx_server *s) {
    if (!s)
        return;
    atomic_store(&s->stopping, true);
    MHD_stop_daemon(s->daemon); /* closes the listening socket too */
    free(s);
}
