/* Buffers mapped ahead of use and given back after (firmware/mem.h, hal/posix/memory_posix.c):
 * the hooks are asked for exactly the range a fill writes or a stage lets go, never for nothing;
 * the Linux backend maps the pages a range spans, no others, and gives back only the pages wholly
 * inside a range (a page it shares with other data keeps that data). */
#define _DEFAULT_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "mem.h"
#include "memory_posix.h"

static struct {
    void *addr;
    size_t bytes;
    int calls;
} asked;

static int record(void *addr, size_t bytes)
{
    asked.addr = addr, asked.bytes = bytes, asked.calls++;
    return -EINVAL; /* as an old kernel answers: the caller goes on */
}

static void test_fill_asks_for_its_range(void **state)
{
    (void)state;
    static uint8_t buf[10000];
    memset(&asked, 0, sizeof(asked));
    static const struct mem_platform recorder = {record, NULL};
    mem_use(&recorder);
    mem_fill(buf + 3, 0xAB, 5000);
    assert_int_equal(asked.calls, 1);
    assert_ptr_equal(asked.addr, buf + 3);
    assert_int_equal(asked.bytes, 5000);
    for (size_t i = 0; i < sizeof(buf); i++)
        assert_int_equal(buf[i], i >= 3 && i < 5003 ? 0xAB : 0);
    mem_prefault(NULL, 100); /* nothing to map: the hook is not asked */
    mem_prefault(buf, 0);
    assert_int_equal(asked.calls, 1);
    mem_use(NULL); /* no hook: a fill is a memset */
    mem_fill(buf, 0, sizeof(buf));
    assert_int_equal(asked.calls, 1);
    assert_int_equal(buf[3], 0);
}

/* Pages of @p p (@p pages of them) resident, as a bit mask of the first 64. */
static uint64_t resident(uint8_t *p, size_t pages)
{
    unsigned char vec[64];
    assert_int_equal(mincore(p, pages * (size_t)sysconf(_SC_PAGESIZE), vec), 0);
    uint64_t mask = 0;
    for (size_t i = 0; i < pages; i++)
        mask |= (uint64_t)(vec[i] & 1u) << i;
    return mask;
}

static void test_posix_maps_the_pages_spanned(void **state)
{
    (void)state;
    size_t page = (size_t)sysconf(_SC_PAGESIZE);
    uint8_t *p = mmap(NULL, 32 * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    assert_true(p != MAP_FAILED);
    assert_int_equal(resident(p, 32), 0);
    /* from the middle of page 2 to the first byte of page 6: pages 2 .. 6 */
    int rc = memory_posix_prefault(p + 2 * page + 100, 4 * page - 99), ignored = 0;
    if (rc == -EINVAL) { /* before Linux 5.14 */
        print_message("MADV_POPULATE_WRITE not supported here: nothing mapped ahead\n");
        assert_int_equal(resident(p, 32), 0);
    } else {
        assert_int_equal(rc, 0);
#ifndef __x86_64__ /* make test-arm64: qemu-user takes madvise and does nothing */
        ignored = resident(p, 32) == 0;
        if (ignored)
            print_message("madvise taken and ignored (an emulator?): nothing mapped ahead\n");
#endif
        if (!ignored) {
            assert_int_equal(resident(p, 32), 0x7Cu);
            assert_int_equal(p[2 * page + 100], 0); /* mapped as zeros, writable */
            p[6 * page] = 1;
        }
    }
    /* a range the process has not mapped: an error, nothing else (where madvise is heard) */
    assert_int_equal(munmap(p + 16 * page, 16 * page), 0);
    rc = memory_posix_prefault(p + 20 * page, page);
    if (!ignored)
        assert_true(rc == -ENOMEM || rc == -EFAULT || rc == -EINVAL);
    assert_int_equal(munmap(p, 16 * page), 0);
}

static void test_release_asks_for_its_range(void **state)
{
    (void)state;
    static uint8_t buf[10000];
    static const struct mem_platform recorder = {NULL, record};
    memset(&asked, 0, sizeof(asked));
    mem_use(&recorder);
    mem_release(buf + 7, 9000);
    assert_int_equal(asked.calls, 1);
    assert_ptr_equal(asked.addr, buf + 7);
    assert_int_equal(asked.bytes, 9000);
    mem_release(NULL, 100); /* nothing to give back: the hook is not asked */
    mem_release(buf, 0);
    mem_prefault(buf, 100); /* no prefault hook: nothing asked, nothing done */
    mem_fill(buf, 1, 100);
    assert_int_equal(asked.calls, 1);
    assert_int_equal(buf[99], 1);
    mem_use(NULL);
    mem_release(buf, sizeof(buf)); /* no hook: the pages stay, as written */
    assert_int_equal(buf[99], 1);
}

static void test_posix_gives_back_whole_pages_only(void **state)
{
    (void)state;
    size_t page = (size_t)sysconf(_SC_PAGESIZE);
    uint8_t *p = mmap(NULL, 8 * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    assert_true(p != MAP_FAILED);
    memset(p, 0x5A, 8 * page);
    assert_int_equal(resident(p, 8), 0xFFu);
    /* from the middle of page 1 to the middle of page 5: pages 2 .. 4 given back, 1 and 5 kept */
    assert_int_equal(memory_posix_release(p + page + 100, 4 * page), 0);
    uint64_t left = resident(p, 8); /* before a read maps the zero page there */
    int heard = p[3 * page] == 0;
#ifdef __x86_64__ /* make test-arm64: qemu-user may take madvise and do nothing */
    assert_true(heard);
#endif
    if (heard)
        print_message("pages given back read as zeros\n");
    else
        print_message("madvise taken and ignored (an emulator?): nothing given back\n");
    for (size_t i = 0; i < 8 * page; i++)
        if (i < 2 * page || i >= 5 * page || !heard)
            assert_int_equal(p[i], 0x5A); /* another buffer's bytes, kept */
        else
            assert_int_equal(p[i], 0);
    if (heard)
        assert_int_equal(left, 0xE3u); /* pages 2 .. 4 no longer resident */
    /* a range holding no whole page: nothing given back, no error */
    assert_int_equal(memory_posix_release(p + 100, page), 0);
    assert_int_equal(p[100], 0x5A);
    assert_int_equal(p[page + 99], 0x5A);
    assert_int_equal(munmap(p, 8 * page), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fill_asks_for_its_range),
        cmocka_unit_test(test_posix_maps_the_pages_spanned),
        cmocka_unit_test(test_release_asks_for_its_range),
        cmocka_unit_test(test_posix_gives_back_whole_pages_only),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
