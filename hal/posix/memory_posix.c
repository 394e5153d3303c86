/* Memory mapped ahead of its first use: madvise(MADV_POPULATE_WRITE) on the pages a buffer
 * spans (they are the caller's to write, so mapping them whole maps nothing it would not); and
 * given back after its last: MADV_DONTNEED on the pages wholly inside it. */
#define _DEFAULT_SOURCE
#include "memory_posix.h"

#include <errno.h>
#include <stdint.h>
#include <sys/mman.h>
#include <unistd.h>

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23 /* Linux 5.14, newer than some C libraries' headers */
#endif

int memory_posix_prefault(void *addr, size_t bytes)
{
    long page = sysconf(_SC_PAGESIZE);
    if (page <= 0)
        return -EINVAL;
    uintptr_t mask = (uintptr_t)page - 1u, lo = (uintptr_t)addr & ~mask;
    uintptr_t hi = ((uintptr_t)addr + bytes + mask) & ~mask;
    return madvise((void *)lo, hi - lo, MADV_POPULATE_WRITE) == 0 ? 0 : -errno;
}

int memory_posix_release(void *addr, size_t bytes)
{
    long page = sysconf(_SC_PAGESIZE);
    if (page <= 0)
        return -EINVAL;
    uintptr_t mask = (uintptr_t)page - 1u, lo = ((uintptr_t)addr + mask) & ~mask;
    uintptr_t hi = ((uintptr_t)addr + bytes) & ~mask;
    if (hi <= lo)
        return 0; /* no whole page: nothing to give back */
    return madvise((void *)lo, hi - lo, MADV_DONTNEED) == 0 ? 0 : -errno;
}
