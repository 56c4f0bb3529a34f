/* A tiny test vocabulary (after Box2D's test_macros.h): each test file is
 * one executable whose main runs its cases; a failed check prints where and
 * why and makes the executable exit non-zero. */
#ifndef PFX_TEST_H
#define PFX_TEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int test_failures = 0;
static int test_checks = 0;

#define CHECK(cond)                                                                                \
    do {                                                                                           \
        test_checks++;                                                                             \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);               \
            test_failures++;                                                                       \
        }                                                                                          \
    } while (0)

/* |a - b| <= tol */
#define CHECK_NEAR(a, b, tol)                                                                      \
    do {                                                                                           \
        test_checks++;                                                                             \
        double ca_ = (double)(a), cb_ = (double)(b), ct_ = (double)(tol);                          \
        if (!(fabs(ca_ - cb_) <= ct_)) {                                                           \
            fprintf(stderr, "%s:%d: %s = %.17g, expected %s = %.17g within %g\n", __FILE__,        \
                    __LINE__, #a, ca_, #b, cb_, ct_);                                              \
            test_failures++;                                                                       \
        }                                                                                          \
    } while (0)

#define RUN(test_fn)                                                                               \
    do {                                                                                           \
        int before_ = test_failures;                                                               \
        test_fn();                                                                                 \
        fprintf(stderr, "%s %s\n", test_failures == before_ ? "ok  " : "FAIL", #test_fn);          \
    } while (0)

/* The source tree, for the committed files a test reads: $PFX_SOURCE_DIR,
 * as CTest sets it, or else the directory above this header's. */
static inline const char *test_source_dir(void) {
    static char dir[4096];
    const char *env = getenv("PFX_SOURCE_DIR");
    if (env && *env)
        return env;
    snprintf(dir, sizeof dir, "%s", __FILE__);
    char *cut = strstr(dir, "/tests/test.h");
    if (cut)
        *cut = '\0';
    else
        snprintf(dir, sizeof dir, ".");
    return dir;
}

/* The closing line and the exit status: 0 only if no check failed and at
 * least one ran (a test whose cases all returned early proves nothing). */
#define TEST_EXIT()                                                                                \
    (fprintf(stderr, "%d checks, %d failed%s\n", test_checks, test_failures,                       \
             test_checks == 0 ? " (no check ran)" : ""),                                           \
     test_failures == 0 && test_checks > 0 ? 0 : 1)

#endif
