/* POSIX clock backend: CLOCK_MONOTONIC and nanosleep, waking early on a stop request. */
#define _POSIX_C_SOURCE 200809L
#include "clock_posix.h"

#include <errno.h>
#include <time.h>

static int posix_now_us(void *priv, uint64_t *now_us)
{
    (void)priv;
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) != 0)
        return -errno;
    *now_us = (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
    return 0;
}

static int posix_sleep_us(void *priv, uint64_t duration_us)
{
    (void)priv;
    struct timespec req = {.tv_sec = (time_t)(duration_us / 1000000u),
                           .tv_nsec = (long)(duration_us % 1000000u) * 1000L};
    /* A signal (SIGINT) ends the sleep: the caller then sees the stop request. */
    if (nanosleep(&req, NULL) != 0)
        return errno == EINTR ? -EINTR : -errno;
    return 0;
}

static int posix_clock_safe_state(void *priv)
{
    (void)priv;
    return 0;
}

static const struct hal_clock_ops posix_clock_ops = {
    .now_us = posix_now_us,
    .sleep_us = posix_sleep_us,
    .safe_state = posix_clock_safe_state,
};

void clock_posix_init(struct hal_clock *clock)
{
    clock->ops = &posix_clock_ops;
    clock->priv = NULL;
}

static double cpu_clock_s(clockid_t id)
{
    struct timespec ts;
    if (clock_gettime(id, &ts) != 0)
        return 0.0;
    return (double)ts.tv_sec + (double)ts.tv_nsec / 1e9;
}

double clock_posix_thread_cpu_s(void)
{
    return cpu_clock_s(CLOCK_THREAD_CPUTIME_ID);
}

double clock_posix_process_cpu_s(void)
{
    return cpu_clock_s(CLOCK_PROCESS_CPUTIME_ID);
}
