/* Threads started with every signal blocked (the new thread inherits the mask in force). */
#define _POSIX_C_SOURCE 200809L
#include "thread_posix.h"

#include <signal.h>

int thread_posix_start(pthread_t *thread, size_t stack_bytes, void *(*fn)(void *), void *arg)
{
    pthread_attr_t attr;
    sigset_t all, old;
    sigfillset(&all);
    int rc = pthread_attr_init(&attr);
    if (rc != 0)
        return -rc;
    if (stack_bytes > 0)
        rc = pthread_attr_setstacksize(&attr, stack_bytes);
    if (rc == 0 && (rc = pthread_sigmask(SIG_BLOCK, &all, &old)) == 0) {
        rc = pthread_create(thread, &attr, fn, arg);
        pthread_sigmask(SIG_SETMASK, &old, NULL);
    }
    pthread_attr_destroy(&attr);
    return -rc;
}
