/* Buffers the firmware is about to write, mapped in one call where the platform can. */
#ifndef MEM_H
#define MEM_H

#include <stddef.h>

/** The platform's way to map the pages of [addr, addr + bytes) at once (hal/posix: madvise
 *  MADV_POPULATE_WRITE). @retval 0 @retval -errno */
typedef int (*mem_prefault_fn)(void *addr, size_t bytes);

/** Use @p fn from now on: set once at start, before any stage runs (NULL, the default: the
 *  pages are mapped as they are first touched). */
void mem_use_prefault(mem_prefault_fn fn);

/** Map [addr, addr + bytes), which the caller is about to write, ahead of that. Why: a static
 *  buffer is otherwise mapped a page at a time on first use, a fault every 4 KiB, and those
 *  faults cost more than the mapping itself (`scanner process` of make run's scan: 50,000 of
 *  them, about 0.4 s of its 2.4 s CPU on a virtual machine; mapped in one call a buffer costs a
 *  sixth of that a page). An optimisation only: where the platform cannot, nothing changes. */
void mem_prefault(void *addr, size_t bytes);

/** memset(@p addr, @p byte, @p bytes), its pages mapped first (mem_prefault): for clearing a
 *  large static buffer, whose pages the memset would otherwise fault in one at a time. */
void mem_fill(void *addr, int byte, size_t bytes);

#endif
