/* pfx lsp: the language server for effect files on standard input and
 * output (lsp/server.c does the work). It takes no FILE: the editor sends
 * the documents. Exit status 0 after shutdown then exit, 1 otherwise. */
#include <unistd.h>

#include "commands/commands.h"
#include "lsp/server.h"

int pfx_cmd_lsp(const char *const *operands, int count, const pfx_cli *o) {
    (void)operands;
    (void)o;
    if (count != 0)
        return pfx_cli_usage_error("%s", "lsp takes no FILE: the editor sends the documents");
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    int status = pfx_lsp_serve(STDIN_FILENO, STDOUT_FILENO, &run);
    pfx_diags_print(&run, stderr, false);
    if (run.errors)
        status = EXIT_INVALID;
    pfx_diags_free(&run);
    return status;
}
