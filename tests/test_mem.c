/* Buffers mapped ahead of use (firmware/mem.h, hal/posix/memory_posix.c): the hook is asked for
 * exactly the range a fill writes, never for nothing, and the Linux backend maps the pages a
 * range spans, no others. */
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
    mem_use_prefault(record);
    mem_fill(buf + 3, 0xAB, 5000);
    assert_int_equal(asked.calls, 1);
    assert_ptr_equal(asked.addr, buf + 3);
    assert_int_equal(asked.bytes, 5000);
    for (size_t i = 0; i < sizeof(buf); i++)
        assert_int_equal(buf[i], i >= 3 && i < 5003 ? 0xAB : 0);
    mem_prefault(NULL, 100); /* nothing to map: the hook is not asked */
    mem_prefault(buf, 0);
    assert_int_equal(asked.calls, 1);
    mem_use_prefault(NULL); /* no hook: a fill is a memset */
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fill_asks_for_its_range),
        cmocka_unit_test(test_posix_maps_the_pages_spanned),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
