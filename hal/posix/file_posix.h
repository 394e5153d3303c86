/* Opening a file to read that must be a regular file: a FIFO, a device or a socket planted where
 * a frame, a config or a mesh should be is refused at once instead of blocking the reader. */
#ifndef FILE_POSIX_H
#define FILE_POSIX_H

#include <stdio.h>

/** fopen(@p path, @p mode) for reading, refusing what is not a regular file without waiting for
 *  it (a FIFO would block open() and read() forever: it is opened with O_NONBLOCK, checked with
 *  fstat, and only then used). @p mode is "r" or "rb".
 *  @retval the stream @retval NULL with errno: EISDIR a directory, EINVAL a FIFO, device or
 *  socket, or open's own (ENOENT, ELOOP for a symlink loop, ...) */
FILE *file_open_regular(const char *path, const char *mode);

/** The same, refusing a symbolic link there too (ELOOP): for a file only the scanner writes,
 *  read on behalf of someone who must not be led out of its folder by a link (the web API). */
FILE *file_open_regular_nolink(const char *path, const char *mode);

/** Like file_open_regular, for a descriptor (O_RDONLY | O_CLOEXEC, blocking once checked).
 *  @retval the descriptor @retval -errno */
int file_open_regular_fd(const char *path);

/** strerror(@p err) (a positive errno), saying what file_open_regular's EINVAL means. */
const char *file_strerror(int err);

#endif
