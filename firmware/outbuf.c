/* One static chunk serves every file the firmware writes (one at a time). */
#include "outbuf.h"

#include <errno.h>
#include <math.h>

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static uint8_t chunk[64u * 1024u];

int outbuf_open(struct outbuf *o, const struct hal_storage *st, const char *path)
{
    o->st = st;
    o->used = 0;
    o->rc = hal_storage_open(st, &o->file, path);
    return o->rc;
}

static void flush(struct outbuf *o)
{
    if (o->rc == 0 && o->used > 0)
        o->rc = hal_storage_write(o->st, &o->file, chunk, o->used);
    o->used = 0;
}

void outbuf_put(struct outbuf *o, const void *data, size_t len)
{
    const uint8_t *p = data;
    while (len > 0 && o->rc == 0) {
        if (o->used == sizeof(chunk))
            flush(o);
        size_t n = sizeof(chunk) - o->used < len ? sizeof(chunk) - o->used : len;
        memcpy(chunk + o->used, p, n);
        o->used += n;
        p += n;
        len -= n;
    }
}

void outbuf_printf(struct outbuf *o, const char *fmt, ...)
{
    char line[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(line, sizeof(line), fmt, ap);
    va_end(ap);
    if (n >= (int)sizeof(line) && o->rc == 0)
        o->rc = -EOVERFLOW; /* a cut line would make a damaged file: a writer's bug, said */
    else if (n > 0)
        outbuf_put(o, line, (size_t)n);
}

/* The decimal digits of @p u at the end of @p end's buffer. @retval their first */
static char *digits(char *end, uint64_t u)
{
    do {
        *--end = (char)('0' + u % 10u);
        u /= 10u;
    } while (u > 0);
    return end;
}

void outbuf_u32(struct outbuf *o, uint32_t v)
{
    char buf[16], *end = buf + sizeof(buf);
    char *p = digits(end, v);
    outbuf_put(o, p, (size_t)(end - p));
}

void outbuf_fixed(struct outbuf *o, double v, unsigned decimals)
{
    static const double scale[10] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9};
    const double product = decimals <= 9u ? fabs(v) * scale[decimals] : NAN;
    if (!(product < 4503599627370496.0)) { /* 2^52: beyond exact integers (or NaN): printf's */
        outbuf_printf(o, "%.*f", (int)(decimals > 9u ? 9u : decimals), v);
        return;
    }
    /* printf rounds the exact value, half to even. The product is rounded once already; only
     * when it landed on a half can that rounding have moved it across one, and then the exact
     * product's remainder (fma) says to which side it lies. */
    double whole = nearbyint(product);
    if (product - floor(product) == 0.5) {
        double rest = fma(fabs(v), scale[decimals], -product);
        whole = rest > 0.0 ? ceil(product) : rest < 0.0 ? floor(product) : whole;
    }
    const uint64_t u = (uint64_t)whole;
    const uint64_t unit = (uint64_t)scale[decimals];
    char buf[40], *end = buf + sizeof(buf), *p = end;
    if (decimals > 0) {
        uint64_t frac = u % unit;
        for (unsigned k = 0; k < decimals; k++, frac /= 10u)
            *--p = (char)('0' + frac % 10u);
        *--p = '.';
    }
    p = digits(p, u / unit);
    if (signbit(v))
        *--p = '-'; /* as printf: "-0.0000" for a negative value that rounds to 0 */
    outbuf_put(o, p, (size_t)(end - p));
}

void outbuf_u32le(struct outbuf *o, uint32_t u)
{
    uint8_t b[4];
    outbuf_u32le_at(b, u);
    if (o->used + 4u > sizeof(chunk)) { /* the chunk's end: outbuf_put flushes it */
        outbuf_put(o, b, 4);
        return;
    }
    /* a mesh's every coordinate comes this way (16 million for make run's): straight in */
    memcpy(chunk + o->used, b, 4);
    o->used += 4;
}

void outbuf_f32le(struct outbuf *o, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof(u));
    outbuf_u32le(o, u);
}

int outbuf_close(struct outbuf *o)
{
    flush(o);
    if (o->rc == 0)
        o->rc = hal_storage_commit(o->st, &o->file);
    if (o->rc != 0)
        hal_storage_abort(o->st, &o->file);
    return o->rc;
}
