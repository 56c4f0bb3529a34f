/* The atomic-file writer: many temporaries open at once (one per frame
 * encoder thread, and a machine may have 64 cores), each renamed into
 * place whole, none left behind. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "output/atomic_file.h"
#include "test.h"

enum { OPEN_AT_ONCE = 100 };

/* Entries of dir other than . and .. */
static int entries(const char *dir) {
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    if (d)
        closedir(d);
    return n;
}

static void test_many_open_at_once(void) {
    char dir[] = "/tmp/pfx-atomic-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    pfx_atomic_file *a[OPEN_AT_ONCE];
    char path[OPEN_AT_ONCE][64];
    int opened = 0;
    for (int i = 0; i < OPEN_AT_ONCE; i++) {
        snprintf(path[i], sizeof path[i], "%s/f%03d", dir, i);
        a[i] = pfx_atomic_open(path[i], &d);
        opened += a[i] != NULL;
        if (a[i])
            fprintf(pfx_atomic_stream(a[i]), "file %d\n", i);
    }
    CHECK(opened == OPEN_AT_ONCE);
    CHECK(d.errors == 0);
    CHECK(entries(dir) == OPEN_AT_ONCE); /* the temporaries, none renamed yet */
    for (int i = 0; i < OPEN_AT_ONCE; i++)
        if (a[i])
            CHECK(pfx_atomic_commit(a[i], i == OPEN_AT_ONCE - 1, &d));
    CHECK(entries(dir) == OPEN_AT_ONCE); /* the final names, no temporary */
    for (int i = 0; i < OPEN_AT_ONCE; i++) {
        char want[32], got[32] = "";
        snprintf(want, sizeof want, "file %d\n", i);
        FILE *f = fopen(path[i], "r");
        CHECK(f != NULL);
        if (f) {
            CHECK(fgets(got, sizeof got, f) != NULL);
            fclose(f);
        }
        CHECK(strcmp(got, want) == 0);
        unlink(path[i]);
    }
    rmdir(dir);
    pfx_diags_free(&d);
}

int main(void) {
    RUN(test_many_open_at_once);
    return TEST_EXIT();
}
