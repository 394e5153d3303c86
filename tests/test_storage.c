/* Atomic, durable writes: the final path holds the old file or the new one, never a torn one. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "storage_posix.h"
#include "test_util.h"

#define DIR "build/test_storage/a/b"

static struct hal_storage st;

static size_t read_all(const char *path, char *buf, size_t cap)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL)
        return (size_t)-1;
    size_t n = fread(buf, 1, cap, f);
    fclose(f);
    return n;
}

static void test_write_then_replace(void **state)
{
    (void)state;
    char buf[64];
    storage_posix_init(&st);
    assert_int_equal(hal_storage_mkdir_p(&st, DIR), 0);
    assert_int_equal(hal_storage_mkdir_p(&st, DIR), 0); /* exists: fine */
    assert_int_equal(hal_storage_write_file(&st, DIR "/f.txt", "first", 5), 0);
    assert_int_equal(read_all(DIR "/f.txt", buf, sizeof(buf)), 5);
    assert_memory_equal(buf, "first", 5);
    assert_int_equal(hal_storage_write_file(&st, DIR "/f.txt", "second!", 7), 0);
    assert_int_equal(read_all(DIR "/f.txt", buf, sizeof(buf)), 7);
    assert_memory_equal(buf, "second!", 7);
    assert_int_equal(test_temporaries_in(DIR), 0); /* no temp file left behind */
}

/* A write that is abandoned half way leaves the old version untouched. */
static void test_abort_keeps_old_version(void **state)
{
    (void)state;
    char buf[64];
    struct hal_file f;
    storage_posix_init(&st);
    assert_int_equal(hal_storage_write_file(&st, DIR "/g.txt", "old", 3), 0);
    assert_int_equal(hal_storage_open(&st, &f, DIR "/g.txt"), 0);
    assert_int_equal(hal_storage_write(&st, &f, "new, but half", 13), 0);
    assert_int_equal(read_all(DIR "/g.txt", buf, sizeof(buf)), 3); /* not visible before commit */
    hal_storage_abort(&st, &f);
    assert_int_equal(read_all(DIR "/g.txt", buf, sizeof(buf)), 3);
    assert_memory_equal(buf, "old", 3);
    assert_int_equal(test_temporaries_in(DIR), 0);
}

static void test_errors_are_reported(void **state)
{
    (void)state;
    storage_posix_init(&st);
    assert_int_equal(hal_storage_write_file(&st, "build/test_storage/missing/x", "x", 1), -ENOENT);
    assert_int_equal(hal_storage_write_file(&st, DIR "/f.txt", "y", 1), 0);
    assert_int_equal(hal_storage_mkdir_p(&st, DIR "/f.txt/sub"), -ENOTDIR);
    /* /dev/full: every write fails with ENOSPC, as a full disk does */
    struct hal_file f = {.fd = -1};
    strcpy(f.temp_path, "build/test_storage/unused");
    FILE *full = fopen("/dev/full", "w");
    assert_non_null(full);
    f.fd = fileno(full);
    assert_int_equal(hal_storage_write(&st, &f, "data", 4), -ENOSPC);
    fclose(full);
}

/* A symlink planted where a temporary file used to be named (FILE.tmp) is never followed: the
 * file it points at stays as it was, and the write lands where it should. */
static void test_planted_symlink_not_followed(void **state)
{
    (void)state;
    char buf[64];
    storage_posix_init(&st);
    assert_int_equal(hal_storage_mkdir_p(&st, DIR), 0);
    FILE *f = fopen(DIR "/victim", "w");
    assert_non_null(f);
    fputs("precious", f);
    fclose(f);
    unlink(DIR "/config.ini.tmp");
    assert_int_equal(symlink("victim", DIR "/config.ini.tmp"), 0);
    assert_int_equal(hal_storage_write_file(&st, DIR "/config.ini", "[scan]\n", 7), 0);
    assert_int_equal(read_all(DIR "/victim", buf, sizeof(buf)), 8);
    assert_memory_equal(buf, "precious", 8);
    assert_int_equal(read_all(DIR "/config.ini", buf, sizeof(buf)), 7);
    unlink(DIR "/config.ini.tmp");
}

/* What interrupted writes left is swept at the next start; nothing else is touched, and a
 * planted link is removed itself, never what it points at. */
static void test_sweep_removes_temporaries(void **state)
{
    (void)state;
    char buf[64];
    struct hal_file f;
    storage_posix_init(&st);
    assert_int_equal(hal_storage_mkdir_p(&st, DIR "/sweep"), 0);
    assert_int_equal(hal_storage_write_file(&st, DIR "/sweep/keep.txt", "kept", 4), 0);
    assert_int_equal(hal_storage_open(&st, &f, DIR "/sweep/cut.txt"), 0); /* a kill, here */
    assert_int_equal(hal_storage_write(&st, &f, "half", 4), 0);
    close(f.fd);
    unlink(DIR "/sweep/link.tmp.AbC123");
    assert_int_equal(symlink("keep.txt", DIR "/sweep/link.tmp.AbC123"), 0);
    assert_int_equal(test_temporaries_in(DIR "/sweep"), 2);
    assert_int_equal(hal_storage_sweep(&st, DIR "/sweep"), 0);
    assert_int_equal(test_temporaries_in(DIR "/sweep"), 0);
    assert_int_equal(read_all(DIR "/sweep/keep.txt", buf, sizeof(buf)), 4);
    assert_int_equal(access(DIR "/sweep/cut.txt", F_OK), -1);
    assert_int_equal(hal_storage_sweep(&st, DIR "/no-such-dir"), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_write_then_replace),
        cmocka_unit_test(test_abort_keeps_old_version),
        cmocka_unit_test(test_errors_are_reported),
        cmocka_unit_test(test_planted_symlink_not_followed),
        cmocka_unit_test(test_sweep_removes_temporaries),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
