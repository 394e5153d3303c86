/* Large static buffers: mapped in one call before a stage writes them, and given back once no
 * later stage reads them, where the platform can. */
#ifndef MEM_H
#define MEM_H

#include <stddef.h>

/** The platform's ways to map and to give back pages (hal/posix: madvise). Either may be NULL. */
struct mem_platform {
    /** Map the pages of [addr, addr + bytes) at once (MADV_POPULATE_WRITE).
     *  @retval 0 @retval -errno */
    int (*prefault)(void *addr, size_t bytes);
    /** Give back the pages wholly inside [addr, addr + bytes): they read as zeros if touched
     *  again (MADV_DONTNEED). @retval 0 @retval -errno */
    int (*release)(void *addr, size_t bytes);
};

/** Use @p p from now on: set once at start, before any stage runs (NULL, the default: pages are
 *  mapped as they are first touched and kept until the process ends). */
void mem_use(const struct mem_platform *p);

/** Map [addr, addr + bytes), which the caller is about to write, ahead of that. Why: a static
 *  buffer is otherwise mapped a page at a time on first use, a fault every 4 KiB, and those
 *  faults cost more than the mapping itself (`scanner process` of make run's scan: 50,000 of
 *  them, about 0.4 s of its 2.4 s CPU on a virtual machine; mapped in one call a buffer costs a
 *  sixth of that a page). An optimisation only: where the platform cannot, nothing changes. */
void mem_prefault(void *addr, size_t bytes);

/** [addr, addr + bytes) will not be read again before it is written whole: its pages may be
 *  given back (their contents then read as zeros). Why: BSS pages once touched stay resident, so
 *  without it the peak memory of a scan is the sum of its stages' buffers (the view's frames and
 *  the decoder beside the fusion grid and the texture) rather than the largest of them. Where
 *  the platform cannot, the pages stay as they are. */
void mem_release(void *addr, size_t bytes);

/** memset(@p addr, @p byte, @p bytes), its pages mapped first (mem_prefault): for clearing a
 *  large static buffer, whose pages the memset would otherwise fault in one at a time. */
void mem_fill(void *addr, int byte, size_t bytes);

#endif
