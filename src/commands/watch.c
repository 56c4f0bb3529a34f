/* pfx watch FILE... -o DIR: pfx render in a loop, once now and again on
 * every save of a file or of what it reads; the manifest skips the files
 * that did not change. Stops on Control-C, between two renders. */
#include <stdio.h>

#include "commands/commands.h"
#include "jobs/file_watch.h"
#include "output/atomic_file.h"

/* The watch the signal thread stops (one `pfx watch` a process). */
static pfx_file_watch *stopping;

static void on_stop_signal(int sig) {
    (void)sig;
    pfx_file_watch_stop(stopping);
}

/* What a file reads, as the render's own load found it (a file that does
 * not compile is watched alone, until it does). */
static void watch_inputs(void *ctx, const pfx_effect *e) { pfx_file_watch_add_effect(ctx, e); }

int pfx_cmd_watch(const char *const *operands, int count, const pfx_cli *o) {
    if (count < 1 || !o->output)
        return pfx_cli_usage_error("%s", "watch needs a FILE and -o DIR");
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    pfx_file_watch *w = pfx_file_watch_create(&run);
    pfx_diags_print(&run, stderr, false);
    pfx_diags_free(&run);
    if (!w)
        return EXIT_INVALID;
    /* One file's error must not stop the others from rendering. */
    pfx_cli ro = *o;
    ro.keep_going = true;
    stopping = w;
    pfx_atomic_set_stop_hook(on_stop_signal);
    int status = 0;
    do {
        /* The files watched before they are read: a save during the
         * render is not missed. Each is read once a round: what it reads
         * is watched from the render's own load. */
        pfx_file_watch_reset(w);
        for (int i = 0; i < count; i++)
            pfx_file_watch_add(w, operands[i]);
        status = pfx_cli_render_each(operands, count, &ro, watch_inputs, w);
        if (status == EXIT_USAGE)
            break;
        if (!o->quiet)
            fprintf(stderr, "pfx: watching %d file%s for changes; Control-C stops\n", count,
                    count == 1 ? "" : "s");
    } while (pfx_file_watch_wait(w));
    pfx_atomic_set_stop_hook(NULL);
    pfx_file_watch_destroy(w);
    return status == EXIT_USAGE ? EXIT_USAGE : 0;
}
