/* Slice arithmetic (jobs/slice.h): integer only, so every process of an
 * array computes the same cuts. */
#include "jobs/slice.h"

#include <errno.h>
#include <stdlib.h>

bool pfx_slice_range(long first, long last, long index, long count, long *s_first, long *s_last) {
    long long frames = (long long)last - first + 1;
    *s_first = first + (long)(frames * index / count);
    *s_last = first + (long)(frames * (index + 1) / count) - 1;
    return *s_first <= *s_last;
}

bool pfx_slice_range_step(long first, long last, long step, long index, long count, long *s_first,
                          long *s_last) {
    long a, b;
    bool any = pfx_slice_range(0, (last - first) / step, index, count, &a, &b);
    *s_first = first + a * step;
    *s_last = first + b * step;
    return any;
}

bool pfx_slice_index_from_env(const char *name, long count, long *index) {
    const char *v = getenv(name);
    if (!v || !*v || *v == '-' || *v == '+')
        return false;
    char *end;
    errno = 0;
    long i = strtol(v, &end, 10);
    if (errno || *end || i < 0 || i >= count)
        return false;
    *index = i;
    return true;
}
