/* Memory mapped ahead of its first use, on Linux (firmware/mem.h's hook). */
#ifndef MEMORY_POSIX_H
#define MEMORY_POSIX_H

#include <stddef.h>

/** Map the pages of [addr, addr + bytes) writable now: madvise(MADV_POPULATE_WRITE), Linux
 *  5.14 and later. @retval 0 @retval -EINVAL (an older kernel) or another -errno */
int memory_posix_prefault(void *addr, size_t bytes);

#endif
