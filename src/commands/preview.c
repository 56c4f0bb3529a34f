/* pfx preview FILE: a live session (jobs/session.c) served over HTTP
 * (serve/) to the page embedded in the binary, until Control-C. Prints the
 * URL first, opens it in the desktop's browser when there is a display. */
#include <errno.h>
#include <fcntl.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "commands/commands.h"
#include "output/atomic_file.h"
#include "serve/compare.h"
#include "serve/server.h"

extern char **environ;

/* The signal thread writes here; main waits on the other end. */
static int stop_pipe[2] = {-1, -1};

static void on_stop_signal(int sig) {
    (void)sig;
    ssize_t w = write(stop_pipe[1], "x", 1);
    (void)w;
}

/* xdg-open URL, its output discarded, not waited for (its child is the
 * browser): only with a display, since a server over SSH has no browser
 * to open. */
static void open_browser(const char *url) {
    const char *x = getenv("DISPLAY"), *w = getenv("WAYLAND_DISPLAY");
    if (!(x && *x) && !(w && *w))
        return;
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
    char *argv[] = {"xdg-open", (char *)url, NULL};
    pid_t pid;
    posix_spawnp(&pid, "xdg-open", &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
}

int pfx_cmd_preview(const char *const *operands, int count, const pfx_cli *o) {
    if (count != 1)
        return pfx_cli_usage_error("%s", count ? "preview takes one FILE" : "preview needs a FILE");
    pfx_renderer_kind kind;
    if (!pfx_cli_renderer_kind(o, &kind))
        return EXIT_USAGE;
    const char *host = o->host ? o->host : "127.0.0.1";
    if (o->host && strcmp(host, "127.0.0.1") && strcmp(host, "::1"))
        fprintf(stderr,
                "pfx: warning: serving on %s, not 127.0.0.1: anyone who can reach it and has the "
                "token can read the effect and what it reads\n",
                host);
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    int status = EXIT_INVALID;
    pfx_session_options so = {
        .path = operands[0], .compile = o->compile, .renderer = kind, .max_memory = o->max_memory};
    pfx_session *session = NULL;
    pfx_server *server = NULL;
    pfx_compare *compare = NULL;
    if (pipe(stop_pipe)) {
        pfx_diag_error(&run, PFX_RULE_OUT_OF_MEMORY, "cannot make a pipe: %s", strerror(errno));
        goto done;
    }
    /* A file that is not there is a typo on the command line, not a save
     * yet to come: say so and stop. One that does not compile is served,
     * its diagnostics on the page until a good save. */
    if (access(operands[0], R_OK) != 0) {
        pfx_diag_error(&run, PFX_RULE_MISSING_FILE, "cannot open '%s': %s", operands[0],
                       strerror(errno));
        goto done;
    }
    /* The port first: one in use fails before anything is compiled. */
    pfx_server_options sv = {.host = host, .port = o->port};
    server = pfx_server_start(&sv, &run);
    if (!server)
        goto done;
    /* The session after: pfx_server_start gave the routes no session yet,
     * and no request can pass the token check before the URL is printed. */
    session = pfx_session_create(&so, &run);
    if (!session)
        goto done;
    pfx_server_set_session(server, session);
    /* A/B against another file or seed: none until --compare or the page
     * asks for one. */
    compare = pfx_compare_create(&so);
    if (!compare) {
        pfx_diag_error(&run, PFX_RULE_OUT_OF_MEMORY, "out of memory for the comparison");
        goto done;
    }
    if (o->compare && !pfx_compare_set(compare, o->compare, false, 0, &run))
        goto done;
    pfx_server_set_compare(server, compare);
    char url[256];
    snprintf(url, sizeof url, "http://%s%s%s:%u/?token=%s", strchr(host, ':') ? "[" : "", host,
             strchr(host, ':') ? "]" : "", pfx_server_port(server), pfx_server_token(server));
    printf("%s\n", url);
    fflush(stdout);
    if (!o->quiet)
        fprintf(stderr, "pfx: previewing '%s'; Control-C stops\n", operands[0]);
    if (!o->no_open)
        open_browser(url);
    pfx_atomic_set_stop_hook(on_stop_signal);
    char c;
    while (read(stop_pipe[0], &c, 1) < 0 && errno == EINTR)
        ;
    pfx_atomic_set_stop_hook(NULL);
    status = 0;
done:
    /* Waits end, then the connections, then the threads behind them. */
    if (session)
        pfx_session_stop(session);
    pfx_server_stop(server);
    pfx_compare_destroy(compare);
    pfx_session_destroy(session);
    pfx_diags_print(&run, stderr, false);
    pfx_diags_free(&run);
    return status;
}
