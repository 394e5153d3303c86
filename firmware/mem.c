/* The platform's memory hooks (mem.h): one pointer, set at start. */
#include "mem.h"

#include <string.h>

static const struct mem_platform *platform;

void mem_use(const struct mem_platform *p)
{
    platform = p;
}

void mem_prefault(void *addr, size_t bytes)
{
    if (platform != NULL && platform->prefault != NULL && addr != NULL && bytes > 0)
        (void)platform->prefault(addr, bytes); /* a platform that cannot maps pages as they come */
}

void mem_release(void *addr, size_t bytes)
{
    if (platform != NULL && platform->release != NULL && addr != NULL && bytes > 0)
        (void)platform->release(addr, bytes); /* one that cannot keeps them: only memory lost */
}

void mem_fill(void *addr, int byte, size_t bytes)
{
    mem_prefault(addr, bytes);
    memset(addr, byte, bytes);
}
