/* base/regular_file.h: O_NONBLOCK for the open, fstat for the kind, then
 * the descriptor back in blocking mode for plain reads. */
#include "base/regular_file.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int pfx_open_regular(const char *path, bool follow_links) {
    int flags = O_RDONLY | O_NONBLOCK | O_CLOEXEC | (follow_links ? 0 : O_NOFOLLOW);
    int fd = open(path, flags);
    if (fd < 0) {
        if (!follow_links && errno == ELOOP)
            errno = PFX_ENOTREG;
        return -1;
    }
    struct stat st;
    int err = 0;
    if (fstat(fd, &st) != 0)
        err = errno;
    else if (!S_ISREG(st.st_mode))
        err = PFX_ENOTREG;
    else if (fcntl(fd, F_SETFL, 0) != 0)
        err = errno;
    if (err) {
        close(fd);
        errno = err;
        return -1;
    }
    return fd;
}

const char *pfx_file_strerror(int errnum) {
    return errnum == PFX_ENOTREG ? "not a regular file" : strerror(errnum);
}
