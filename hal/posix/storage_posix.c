/* POSIX storage backend: atomic, durable file writes as SQLite does them. */
#define _POSIX_C_SOURCE 200809L
#include "storage_posix.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Temporary files are named FILE.tmp.XXXXXX: a name nobody can plant a link at in advance. */
#define TEMP_SUFFIX ".tmp."
#define TEMP_RANDOM "XXXXXX"

static int posix_mkdir_p(void *priv, const char *path)
{
    (void)priv;
    char buf[HAL_MAX_PATH];
    size_t len = strlen(path);
    if (len == 0 || len >= sizeof(buf))
        return -ENAMETOOLONG;
    memcpy(buf, path, len + 1);
    /* Create each parent in turn; an existing directory is fine. */
    for (size_t i = 1; i <= len; i++) {
        if (buf[i] != '/' && buf[i] != '\0')
            continue;
        char saved = buf[i];
        buf[i] = '\0';
        if (mkdir(buf, 0755) != 0 && errno != EEXIST)
            return -errno;
        buf[i] = saved;
    }
    struct stat st;
    if (stat(path, &st) != 0)
        return -errno;
    return S_ISDIR(st.st_mode) ? 0 : -ENOTDIR;
}

static int posix_open_atomic(void *priv, struct hal_file *file, const char *path)
{
    (void)priv;
    file->fd = -1;
    int n1 = snprintf(file->final_path, sizeof(file->final_path), "%s", path);
    int n2 = snprintf(file->temp_path, sizeof(file->temp_path), "%s" TEMP_SUFFIX TEMP_RANDOM, path);
    if (n1 < 0 || n2 < 0 || (size_t)n2 >= sizeof(file->temp_path))
        return -ENAMETOOLONG;
    /* mkstemp creates a new file of a name of its own (O_CREAT | O_EXCL): a symlink or a file
     * someone planted in the directory is never followed nor overwritten. What a crash leaves
     * is removed by posix_sweep at the next start. */
    file->fd = mkstemp(file->temp_path);
    if (file->fd < 0)
        return -errno;
    if (fcntl(file->fd, F_SETFD, FD_CLOEXEC) != 0 || fchmod(file->fd, 0644) != 0) {
        int rc = -errno;
        close(file->fd);
        file->fd = -1;
        unlink(file->temp_path);
        return rc;
    }
    return 0;
}

static int posix_write(void *priv, struct hal_file *file, const void *data, size_t len)
{
    (void)priv;
    const unsigned char *p = data;
    while (len > 0) {
        ssize_t n = write(file->fd, p, len);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return -errno;
        }
        if (n == 0)
            return -ENOSPC;
        p += n;
        len -= (size_t)n;
    }
    return 0;
}

/* fsync the directory holding @p path so that the rename itself survives power loss. */
static int fsync_parent_dir(const char *path)
{
    char dir[HAL_MAX_PATH];
    const char *slash = strrchr(path, '/');
    if (slash == NULL) {
        strcpy(dir, ".");
    } else {
        size_t n = (size_t)(slash - path);
        if (n >= sizeof(dir))
            return -ENAMETOOLONG;
        memcpy(dir, path, n);
        dir[n == 0 ? 1 : n] = '\0';
        if (n == 0)
            dir[0] = '/';
    }
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0)
        return -errno;
    int rc = fsync(fd) == 0 ? 0 : -errno;
    close(fd);
    return rc;
}

static int posix_commit(void *priv, struct hal_file *file)
{
    (void)priv;
    int rc = 0;
    if (fsync(file->fd) != 0)
        rc = -errno;
    if (close(file->fd) != 0 && rc == 0)
        rc = -errno;
    file->fd = -1;
    if (rc != 0)
        return rc;
    if (rename(file->temp_path, file->final_path) != 0)
        return -errno;
    return fsync_parent_dir(file->final_path);
}

static void posix_abort(void *priv, struct hal_file *file)
{
    (void)priv;
    if (file->fd >= 0)
        close(file->fd);
    file->fd = -1;
    unlink(file->temp_path);
}

static int posix_safe_state(void *priv)
{
    (void)priv;
    return 0;
}

/* @retval 1 when @p name is a temporary file of open_atomic: NAME.tmp.XXXXXX */
static int is_temporary(const char *name)
{
    size_t n = strlen(name), tail = strlen(TEMP_SUFFIX TEMP_RANDOM);
    return n > tail && strncmp(name + n - tail, TEMP_SUFFIX, strlen(TEMP_SUFFIX)) == 0;
}

static int posix_sweep(void *priv, const char *dir)
{
    (void)priv;
    DIR *d = opendir(dir);
    if (d == NULL)
        return errno == ENOENT ? 0 : -errno;
    int rc = 0;
    for (struct dirent *e = readdir(d); e != NULL; e = readdir(d)) {
        /* unlinkat removes a planted symlink itself, never its target */
        if (is_temporary(e->d_name) && unlinkat(dirfd(d), e->d_name, 0) != 0 && rc == 0)
            rc = -errno;
    }
    closedir(d);
    return rc;
}

static const struct hal_storage_ops posix_storage_ops = {
    .mkdir_p = posix_mkdir_p,
    .open_atomic = posix_open_atomic,
    .write = posix_write,
    .commit = posix_commit,
    .abort = posix_abort,
    .safe_state = posix_safe_state,
    .sweep = posix_sweep,
};

void storage_posix_init(struct hal_storage *st)
{
    st->ops = &posix_storage_ops;
    st->priv = NULL;
}
