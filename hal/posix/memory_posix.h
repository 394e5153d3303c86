/* Memory mapped ahead of its first use and given back after its last, on Linux (firmware/mem.h's
 * hooks). */
#ifndef MEMORY_POSIX_H
#define MEMORY_POSIX_H

#include <stddef.h>

/** Map the pages of [addr, addr + bytes) writable now: madvise(MADV_POPULATE_WRITE), Linux
 *  5.14 and later. @retval 0 @retval -EINVAL (an older kernel) or another -errno */
int memory_posix_prefault(void *addr, size_t bytes);

/** Give back the pages wholly inside [addr, addr + bytes) (a page partly outside it may hold
 *  another buffer's data, so it stays): madvise(MADV_DONTNEED); on a private anonymous mapping
 *  (BSS) they read as zeros if touched again. @retval 0 (also for a range holding no whole page)
 *  @retval -errno */
int memory_posix_release(void *addr, size_t bytes);

#endif
