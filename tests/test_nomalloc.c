/* Nothing allocates once a scan has started: this binary interposes malloc, calloc, realloc and
 * free (symbol interposition also catches calls from shared libraries, which --wrap does not)
 * and counts the calls made during a whole view. Under ASan the sanitizer owns malloc, so the
 * count comes from its allocation hooks instead. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"

static volatile int counting;
static volatile unsigned long alloc_calls;

#if SAN
/* From <sanitizer/allocator_interface.h>, which GCC's packages do not ship; libasan exports it. */
int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void *, size_t),
                                              void (*free_hook)(const volatile void *));
static void on_malloc(const volatile void *ptr, size_t size)
{
    (void)ptr;
    (void)size;
    if (counting)
        alloc_calls++;
}
static void on_free(const volatile void *ptr)
{
    (void)ptr;
    if (counting)
        alloc_calls++;
}
static void install_counter(void)
{
    __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free);
}
#else
extern void *__libc_malloc(size_t size);
extern void *__libc_calloc(size_t n, size_t size);
extern void *__libc_realloc(void *ptr, size_t size);
extern void __libc_free(void *ptr);

void *malloc(size_t size)
{
    if (counting)
        alloc_calls++;
    return __libc_malloc(size);
}
void *calloc(size_t n, size_t size)
{
    if (counting)
        alloc_calls++;
    return __libc_calloc(n, size);
}
void *realloc(void *ptr, size_t size)
{
    if (counting)
        alloc_calls++;
    return __libc_realloc(ptr, size);
}
void free(void *ptr)
{
    if (counting && ptr != NULL)
        alloc_calls++;
    __libc_free(ptr);
}
static void install_counter(void) {}
#endif

/* The counter itself must see allocations, or a zero below would prove nothing. */
static void test_counter_sees_allocations(void **state)
{
    (void)state;
    install_counter();
    counting = 1;
    alloc_calls = 0;
    char *volatile p = malloc(64);
    free(p);
    counting = 0;
    assert_true(alloc_calls >= 2);
}

/* Capture, decode, triangulate, normals and the PLY write. */
static void test_no_allocation_during_a_view(void **state)
{
    (void)state;
    static struct test_rig t;
    install_counter();
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "sphere");
    assert_int_equal(test_rig_start(&t), 0);
    struct scan_view view;
    struct scan_view_info info;
    alloc_calls = 0;
    counting = 1;
    int rc = scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &info);
    int rc_save =
        rc == 0 ? scan_save_cloud_at_turntable_pose(&t, &view, "build/test_nomalloc.ply") : rc;
    counting = 0;
    assert_int_equal(rc, 0);
    assert_int_equal(rc_save, 0);
    assert_true(info.valid_points > 100000);
    print_message("allocator calls during the view: %lu\n", (unsigned long)alloc_calls);
    assert_int_equal(alloc_calls, 0);
    test_rig_stop(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_counter_sees_allocations),
        cmocka_unit_test(test_no_allocation_during_a_view),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
