/* The platform's prefault hook (mem.h): one pointer, set at start. */
#include "mem.h"

#include <string.h>

static mem_prefault_fn prefault;

void mem_use_prefault(mem_prefault_fn fn)
{
    prefault = fn;
}

void mem_prefault(void *addr, size_t bytes)
{
    if (prefault != NULL && addr != NULL && bytes > 0)
        (void)prefault(addr, bytes); /* a platform that cannot maps the pages as they come */
}

void mem_fill(void *addr, int byte, size_t bytes)
{
    mem_prefault(addr, bytes);
    memset(addr, byte, bytes);
}
