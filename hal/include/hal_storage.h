/* Storage interface: durable, atomic file writes (temp file, fsync, rename, fsync of the
 * directory). */
#ifndef HAL_STORAGE_H
#define HAL_STORAGE_H

#include <stddef.h>

/** An open atomic write: nothing is visible at the final path until commit. */
struct hal_file {
    int fd;               /**< backend handle, -1 when closed */
    char final_path[512]; /**< where the file appears on commit */
    char temp_path[512];  /**< where it is written meanwhile */
};

struct hal_storage_ops {
    /** Create a directory and its parents. @retval 0 ok (also if it exists) @retval -errno */
    int (*mkdir_p)(void *priv, const char *path);
    /** Start an atomic write of @p path. @retval 0 ok @retval -errno */
    int (*open_atomic)(void *priv, struct hal_file *file, const char *path);
    /** Append bytes. @retval 0 all written @retval -ENOSPC disk full @retval -errno */
    int (*write)(void *priv, struct hal_file *file, const void *data, size_t len);
    /** fsync, rename over the final path, fsync the directory. @retval 0 ok @retval -errno */
    int (*commit)(void *priv, struct hal_file *file);
    /** Drop the temp file; the old version at the final path stays. Always succeeds. */
    void (*abort)(void *priv, struct hal_file *file);
    /** Nothing to make safe; present so that every device has the op. */
    int (*safe_state)(void *priv);
    /** Optional: remove the temporary files that interrupted writes left in directory @p dir.
     *  @retval 0 ok (also when there were none) @retval -errno */
    int (*sweep)(void *priv, const char *dir);
};

struct hal_storage {
    const struct hal_storage_ops *ops;
    void *priv;
};

/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_storage_mkdir_p(const struct hal_storage *st, const char *path);
/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_storage_open(const struct hal_storage *st, struct hal_file *file, const char *path);
/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_storage_write(const struct hal_storage *st, struct hal_file *file, const void *data,
                      size_t len);
/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_storage_commit(const struct hal_storage *st, struct hal_file *file);
/** Abort an open write; safe on a file that is not open. */
void hal_storage_abort(const struct hal_storage *st, struct hal_file *file);
/** Remove what interrupted writes left in @p dir. @retval -ENOSYS when the backend lacks the op;
 *  otherwise what the op returns. */
int hal_storage_sweep(const struct hal_storage *st, const char *dir);
/** Write a whole buffer atomically. @retval 0 ok @retval -errno, and the old file is untouched */
int hal_storage_write_file(const struct hal_storage *st, const char *path, const void *data,
                           size_t len);

#endif
