/* Regular files only, checked before the first read (file_posix.h says why). */
#define _POSIX_C_SOURCE 200809L
#include "file_posix.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* @p flags: more of open()'s (O_NOFOLLOW) */
static int open_regular(const char *path, int flags)
{
    /* O_NONBLOCK: opening a FIFO must not wait for a writer */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | flags);
    struct stat st;
    if (fd < 0)
        return -errno;
    int rc = 0;
    if (fstat(fd, &st) != 0)
        rc = -errno;
    else if (!S_ISREG(st.st_mode))
        rc = S_ISDIR(st.st_mode) ? -EISDIR : -EINVAL;
    else if (fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK) != 0)
        rc = -errno;
    if (rc != 0) {
        close(fd);
        return rc;
    }
    return fd;
}

int file_open_regular_fd(const char *path)
{
    return open_regular(path, 0);
}

/* A descriptor as a stream, or NULL with errno. */
static FILE *stream_of(int fd, const char *mode)
{
    if (fd < 0) {
        errno = -fd;
        return NULL;
    }
    FILE *f = fdopen(fd, mode);
    if (f == NULL) {
        int e = errno;
        close(fd);
        errno = e;
    }
    return f;
}

FILE *file_open_regular(const char *path, const char *mode)
{
    return stream_of(open_regular(path, 0), mode);
}

FILE *file_open_regular_nolink(const char *path, const char *mode)
{
    return stream_of(open_regular(path, O_NOFOLLOW), mode);
}

const char *file_strerror(int err)
{
    return err == EINVAL ? "not a regular file (a pipe, device or socket)" : strerror(err);
}
