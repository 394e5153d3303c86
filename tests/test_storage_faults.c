/* Storage under failure, as SQLite tests its commits: the Nth write, fsync or rename of a view's
 * save fails (or the disk is full), for every N; each file must then be its old version or its
 * new one, never torn, with no temporary file left, and the failure reported. The system calls
 * are wrapped at link time (-Wl,--wrap), so the real storage backend runs unchanged. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "hal.h"
#include "storage_posix.h"
#include "test_util.h"

#define DIR "build/test_storage_faults"

enum op { OP_WRITE, OP_FSYNC, OP_RENAME, OP_COUNT };
static const char *const op_name[OP_COUNT] = {"write", "fsync", "rename"};
static unsigned long calls[OP_COUNT];
static unsigned long fail_at[OP_COUNT]; /* 1-based call to fail; 0 = none */
static int fail_errno = EIO;

static int hit(enum op op)
{
    return ++calls[op] == fail_at[op];
}

ssize_t __real_write(int fd, const void *buf, size_t n);
int __real_fsync(int fd);
int __real_rename(const char *from, const char *to);

ssize_t __wrap_write(int fd, const void *buf, size_t n)
{
    if (hit(OP_WRITE)) {
        errno = fail_errno;
        return -1;
    }
    /* short writes, as a nearly full disk or a signal gives them: the backend must loop */
    return __real_write(fd, buf, n > 4096 ? n / 2 : n);
}

int __wrap_fsync(int fd)
{
    if (hit(OP_FSYNC)) {
        errno = fail_errno;
        return -1;
    }
    return __real_fsync(fd);
}

int __wrap_rename(const char *from, const char *to)
{
    if (hit(OP_RENAME)) {
        errno = fail_errno;
        return -1;
    }
    return __real_rename(from, to);
}

/* A view's save in miniature: a frame, the cloud and view.ini (written last). */
#define FILES 3
static const char *const names[FILES] = {"frame_00.png", "cloud.ply", "view.ini"};
static const size_t sizes[FILES] = {70000, 150000, 300};
static uint8_t old_data[FILES][150000], new_data[FILES][150000];

static void path_of(int k, char *buf, size_t len)
{
    snprintf(buf, len, DIR "/%s", names[k]);
}

static void reset_old_versions(struct hal_storage *st)
{
    char path[256];
    memset(fail_at, 0, sizeof(fail_at));
    for (int k = 0; k < FILES; k++) {
        path_of(k, path, sizeof(path));
        assert_int_equal(hal_storage_write_file(st, path, old_data[k], sizes[k]), 0);
    }
}

/* The save, stopping at the first error as the scanner does. @retval 0 or the error */
static int save_view(struct hal_storage *st)
{
    char path[256];
    for (int k = 0; k < FILES; k++) {
        path_of(k, path, sizeof(path));
        int rc = hal_storage_write_file(st, path, new_data[k], sizes[k]);
        if (rc != 0)
            return rc;
    }
    return 0;
}

/* @retval 0 old, 1 new; fails the test if the file is anything else */
static int version_of(int k)
{
    static uint8_t buf[200000];
    char path[256];
    path_of(k, path, sizeof(path));
    assert_int_equal(test_temporaries_in(DIR), 0); /* no temporary file left behind */
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    size_t n = fread(buf, 1, sizeof(buf), f);
    fclose(f);
    if (n == sizes[k] && memcmp(buf, new_data[k], n) == 0)
        return 1;
    if (n == sizes[k] && memcmp(buf, old_data[k], n) == 0)
        return 0;
    fail_msg("%s is torn: %zu bytes, neither its old nor its new version", names[k], n);
    return -1;
}

static void test_every_failure_point_leaves_old_or_new(void **state)
{
    (void)state;
    static struct hal_storage st;
    storage_posix_init(&st);
    mkdir("build", 0755);
    mkdir(DIR, 0755);
    for (int k = 0; k < FILES; k++)
        for (size_t i = 0; i < sizes[k]; i++) {
            old_data[k][i] = (uint8_t)(i * 7 + (size_t)k);
            new_data[k][i] = (uint8_t)(i * 13 + 101 + (size_t)k);
        }
    /* How many calls of each kind one save makes. */
    reset_old_versions(&st);
    memset(calls, 0, sizeof(calls));
    assert_int_equal(save_view(&st), 0);
    unsigned long total[OP_COUNT];
    memcpy(total, calls, sizeof(total));
    for (int k = 0; k < FILES; k++)
        assert_int_equal(version_of(k), 1);
    unsigned long runs = 0;
    for (int full = 0; full <= 1; full++) {
        for (int op = 0; op < OP_COUNT; op++) {
            if (full && op != OP_WRITE)
                continue; /* a full disk refuses writes */
            fail_errno = full ? ENOSPC : EIO;
            for (unsigned long n = 1; n <= total[op]; n++) {
                reset_old_versions(&st);
                memset(calls, 0, sizeof(calls));
                fail_at[op] = n;
                int rc = save_view(&st);
                if (rc != -fail_errno)
                    fail_msg("%s %lu of %lu failing: save returned %d, not %d", op_name[op], n,
                             total[op], rc, -fail_errno);
                /* files before the failure are new, those after it old; the failing one is
                 * old, or new when only the directory's fsync after its rename failed */
                int seen_old = 0;
                for (int k = 0; k < FILES; k++) {
                    int v = version_of(k);
                    if (v == 1 && seen_old)
                        fail_msg("%s written after an earlier file failed", names[k]);
                    seen_old |= v == 0;
                }
                runs++;
            }
        }
    }
    print_message("storage: %lu writes, %lu fsyncs, %lu renames per save; %lu failure points "
                  "(EIO and a full disk), each file old or new after every one\n",
                  total[OP_WRITE], total[OP_FSYNC], total[OP_RENAME], runs);
    assert_true(total[OP_WRITE] > FILES && total[OP_FSYNC] >= 2 * FILES &&
                total[OP_RENAME] == FILES);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_failure_point_leaves_old_or_new),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
