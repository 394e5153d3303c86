/* Sub-stripe refinement by interpolating across runs of equal Gray codes along camera rows. */
#include "refine.h"

#include "hal_thread.h"

/* Code of the run that ends just before x0 (dir -1) or starts just after x1 (dir +1), or -1 if
 * that pixel is not valid. */
static int neighbour_code(const struct decode_maps *m, size_t row, uint32_t x, int dir)
{
    long nx = (long)x + dir;
    if (nx < 0 || nx >= (long)m->width || m->reason[row + (size_t)nx] != SCAN_VALID)
        return -1;
    return m->column[row + (size_t)nx];
}

static void refine_run(const struct decode_maps *m, float *column_sub, size_t row, uint32_t x0,
                       uint32_t x1)
{
    int c = m->column[row + x0];
    int left = neighbour_code(m, row, x0, -1), right = neighbour_code(m, row, x1, +1);
    float len = (float)(x1 - x0 + 1);
    float sign = 0.0f;
    if (left == c - 1 && right == c + 1)
        sign = 1.0f; /* columns grow to the right */
    else if (left == c + 1 && right == c - 1)
        sign = -1.0f;
    for (uint32_t x = x0; x <= x1; x++) {
        /* The run covers [c - 0.5, c + 0.5]; pixel centres sit at (k + 0.5) / len of it. */
        float frac = ((float)(x - x0) + 0.5f) / len - 0.5f;
        column_sub[row + x] = (float)c + sign * frac;
    }
}

/* The rows of one part of a refinement. */
struct refine_parts {
    const struct decode_maps *m;
    int enabled;
    float *column_sub;
    unsigned parts;
};

static void refine_rows(void *arg, unsigned k)
{
    const struct refine_parts *p = arg;
    const struct decode_maps *m = p->m;
    for (uint32_t y = m->height * k / p->parts; y < m->height * (k + 1u) / p->parts; y++) {
        size_t row = (size_t)y * m->width;
        uint32_t x = 0;
        while (x < m->width) {
            if (m->reason[row + x] != SCAN_VALID) {
                x++;
                continue;
            }
            uint32_t end = x;
            while (end + 1 < m->width && m->reason[row + end + 1] == SCAN_VALID &&
                   m->column[row + end + 1] == m->column[row + x])
                end++;
            if (p->enabled) {
                refine_run(m, p->column_sub, row, x, end);
            } else {
                for (uint32_t j = x; j <= end; j++)
                    p->column_sub[row + j] = (float)m->column[row + j];
            }
            x = end + 1;
        }
    }
}

int refine_columns(const struct decode_maps *m, const struct hal_thread *threads, int enabled,
                   float *column_sub)
{
    struct refine_parts p = {m, enabled, column_sub, hal_thread_parts(threads, HAL_MAX_PARTS)};
    hal_thread_run(threads, p.parts, refine_rows, &p);
    return 0;
}
