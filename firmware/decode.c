/* Gray-code decoding of a view: each frame's bit read into the pixels as it is handed over. */
#include "decode.h"

#include "lsq.h"
#include "mem.h"

#include <errno.h>
#include <math.h>
#include <string.h>

const char *scan_reason_name(unsigned reason)
{
    static const char *const names[SCAN_REASON_COUNT] = {
        "valid", "shadow", "dark", "low_contrast", "saturated", "inconsistent"};
    return reason < SCAN_REASON_COUNT ? names[reason] : "unknown";
}

/* x86-64's baseline (SSE2) has no byte shuffle to split RGB triples: a clone for SSSE3 and one
 * for AVX2 are built beside it and the loader picks the best the CPU has (GCC target_clones;
 * Arm's NEON needs none). */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("default", "ssse3", "avx2")))
#endif
void decode_rgb_to_grey(const uint8_t *rgb, uint8_t *grey, size_t n, uint32_t saturation_dn)
{
    /* Written without branches and in 16 bits (77 + 150 + 29 = 256: the sum fits), so that
     * GCC vectorises it where the target loads RGB triples in one instruction (NEON ld3 on the
     * boards: 16 pixels a step); it runs over every pixel of every frame of a colour camera. */
    const uint16_t sat = (uint16_t)(saturation_dn < 256u ? saturation_dn : 256u);
    for (size_t i = 0; i < n; i++) {
        uint16_t r = rgb[3 * i], g = rgb[3 * i + 1], b = rgb[3 * i + 2];
        uint16_t mx = r > g ? r : g;
        mx = mx > b ? mx : b;
        uint16_t luma = (uint16_t)((uint16_t)(77u * r + 150u * g + 29u * b) >> 8); /* BT.601 */
        luma = luma < 254u ? luma : 254u;
        grey[i] = mx >= sat ? DECODE_SATURATED : (uint8_t)luma;
    }
}

uint32_t decode_bit_threshold(const struct scan_params *p, uint32_t contrast_dn)
{
    /* The difference of two frames of the same pixel has variance 2 read^2 + shot noise; the
     * shot noise of I and I_inverse together is that of white minus black (they sum to it):
     * sigma^2 = 2 read^2 + contrast / (electrons per grey level). */
    double var = 2.0 * p->read_noise_dn * p->read_noise_dn +
                 (p->electrons_per_dn > 0.0 ? contrast_dn / p->electrons_per_dn : 0.0);
    double t = ceil(p->bit_noise_sigmas * sqrt(var));
    t = t > p->min_bit_diff_dn ? t : p->min_bit_diff_dn;
    return t > 254.0 ? 254u : (uint32_t)t;
}

uint32_t decode_mean_threshold(const struct scan_params *p, uint32_t contrast_dn)
{
    /* A quarter of the pair's threshold, measured (make measure-inverse, docs/performance.md):
     * the same noise model's threshold (sigma^2 = 1.5 read^2 + 0.75 contrast / gain for half
     * the contrast) lost up to 3 points of valid pixels, half the pair's up to 0.6, at grazing
     * incidence, where the read against the mean has sqrt(3) less signal to noise and the
     * unclear bits pile up; a bit decided by its sign near its own stripe edge is at worst one
     * column off (Gray code), and a wrong one far from it is left to the neighbourhood checks. */
    return (decode_bit_threshold(p, contrast_dn) + 3u) / 4u;
}

/* The decoder's own per-pixel planes, their first @p n pixels: mapped ahead (mem_prefault) or
 * given back (mem_release); the rows' map (@p rows 0: not) only where rows are coded, for
 * nothing reads or writes the rows' planes otherwise. */
static void own_planes(struct decode_ctx *d, size_t n, int rows,
                       void (*op)(void *addr, size_t bytes))
{
    op(d->white, n);
    op(d->black, n);
    op(d->column_map, n * sizeof(uint16_t));
    if (rows)
        op(d->row_map, n * sizeof(uint16_t));
}

/* Its working planes, likewise (without rows 7 bytes a pixel fewer: 112 MB of a 16 MP view). */
static void work_planes(struct decode_work *w, size_t n, int rows,
                        void (*op)(void *addr, size_t bytes))
{
    uint8_t *bytes[] = {w->stage[0],       w->stage[1],      w->threshold,  w->mean,
                        w->mean_threshold, w->sat,           w->word_hi[0], w->word_lo[0],
                        w->unclear_hi[0],  w->unclear_lo[0], w->scratch};
    uint8_t *row_bytes[] = {w->word_hi[1], w->word_lo[1], w->unclear_hi[1], w->unclear_lo[1]};
    for (size_t k = 0; k < sizeof(bytes) / sizeof(bytes[0]); k++)
        op(bytes[k], n);
    op(w->unclear_col, n * sizeof(uint16_t));
    if (!rows)
        return;
    for (size_t k = 0; k < sizeof(row_bytes) / sizeof(row_bytes[0]); k++)
        op(row_bytes[k], n);
    op(w->unclear_row, n * sizeof(uint16_t));
}

void decode_release(struct decode_ctx *d)
{
    own_planes(d, HAL_MAX_PIXELS, 1, mem_release); /* a plane's first use writes it whole */
}

int decode_begin(struct decode_ctx *d, struct decode_work *work, const struct scan_params *params,
                 const struct gray_layout *layout, uint32_t proj_width, uint32_t proj_height)
{
    if (params->width == 0 || params->height == 0 || params->width > HAL_MAX_WIDTH ||
        params->height > HAL_MAX_HEIGHT || layout->col_bits == 0 || layout->col_bits > 16 ||
        layout->row_bits > 16 || gray_layout_count(layout) > DECODE_MAX_PATTERNS || work == NULL)
        return -EINVAL;
    d->work = work;
    d->params = *params;
    d->layout = *layout;
    d->proj_width = proj_width;
    d->proj_height = proj_height;
    d->next_pattern = 0;
    for (uint32_t c = 0; c < 256; c++) {
        d->bit_threshold[c] = (uint8_t)decode_bit_threshold(params, c);
        d->mean_threshold_of[c] = (uint8_t)decode_mean_threshold(params, c);
    }
    d->xor_col = gray_code_xor_mask(layout->code, layout->col_bits);
    d->xor_row = gray_code_xor_mask(layout->code, layout->row_bits);
    size_t n = (size_t)params->width * params->height;
    own_planes(d, n, layout->row_bits > 0, mem_prefault);
    work_planes(work, n, layout->row_bits > 0, mem_prefault);
    return 0;
}

/* Pattern @p pattern's bit @p k of the columns or rows: whether it has an inverse, and whether
 * it is that inverse. @retval 0 @retval -1 white, black or outside the layout */
static int pattern_bit(const struct decode_ctx *d, uint32_t pattern, int *is_row, uint32_t *k,
                       int *paired, int *is_inverse)
{
    uint32_t stripes;
    int32_t inverse;
    if (gray_layout_pattern(&d->layout, pattern, is_row, k, is_inverse) != 0)
        return -1;
    gray_layout_bit(&d->layout, *is_row, *k, &stripes, &inverse);
    *paired = inverse >= 0;
    return 0;
}

uint8_t *decode_frame_slot(struct decode_ctx *d, uint32_t pattern)
{
    int is_row, paired, is_inverse;
    uint32_t k;
    if (pattern >= gray_layout_count(&d->layout))
        return NULL;
    if (pattern == GRAY_PATTERN_WHITE)
        return d->white;
    if (pattern == GRAY_PATTERN_BLACK)
        return d->black;
    if (pattern_bit(d, pattern, &is_row, &k, &paired, &is_inverse) != 0)
        return NULL;
    return paired && !is_inverse ? d->work->stage[0] : d->work->stage[1];
}

/* Black handed over: each pixel's thresholds from its contrast and the mean its bits without
 * inverse are read against. The planes of bits are written whole by the first bit read into
 * each (read_bit), so only those no bit reaches are cleared here: clearing them all took half
 * of this step (make bench, 2028 x 1520: 6.4 -> 3.2 ms). (The mean and its threshold cost
 * nothing measurable where every bit has its inverse: a loop of the threshold alone ran
 * slower than this one, measured.) */
static void begin_bits(struct decode_ctx *d, size_t n)
{
    const uint8_t *restrict white = d->white, *restrict black = d->black;
    for (size_t i = 0; i < n; i++) {
        uint8_t contrast = (uint8_t)(white[i] > black[i] ? white[i] - black[i] : 0);
        d->work->threshold[i] = d->bit_threshold[contrast];
        d->work->mean_threshold[i] = d->mean_threshold_of[contrast];
        d->work->mean[i] = (uint8_t)(((unsigned)white[i] + black[i] + 1u) >> 1);
    }
    for (int axis = 0; axis < 2; axis++) {
        uint32_t bits = axis ? d->layout.row_bits : d->layout.col_bits;
        if (bits == 0) /* no rows coded: their planes are not read (columns have a bit at least) */
            continue;
        if (bits <= 8) {
            memset(d->work->word_lo[axis], 0, n);
            memset(d->work->unclear_lo[axis], 0, n);
        }
    }
}

/* read_bit's loop; @p fresh (the plane's first bit) and @p first_sat (the view's first bit) are
 * constants where it is inlined, so that each case is a loop of its own that does not read what
 * it is about to overwrite. */
static inline void read_bit_loop(uint8_t *restrict word, uint8_t *restrict unc,
                                 uint8_t *restrict sat, const uint8_t *restrict pos,
                                 const uint8_t *restrict neg, const uint8_t *restrict thr, size_t n,
                                 const int fresh, const int first_sat)
{
    for (size_t i = 0; i < n; i++) {
        uint8_t a = pos[i], b = neg[i];
        uint8_t up = (uint8_t)(a > b ? a - b : 0), down = (uint8_t)(b > a ? b - a : 0);
        uint8_t w = fresh ? 0u : (uint8_t)(word[i] << 1), u = fresh ? 0u : (uint8_t)(unc[i] << 1);
        word[i] = (uint8_t)(w | (up != 0));
        unc[i] = (uint8_t)(u | ((up | down) <= thr[i]));
        uint8_t both = (a & b) == DECODE_SATURATED;
        sat[i] = (uint8_t)(first_sat ? both : (sat[i] | both));
    }
}

/* Bit @p k of a coordinate into every pixel: the Gray word and the unclear mask take it as their
 * next (lower) bit, in the byte plane of bits 0-7 or of the rest. |I - I_inverse| from two
 * saturating subtractions, compared with the pixel's own threshold; a pair is saturated when
 * both frames reached DECODE_SATURATED (one saturated frame still says which is brighter). Only
 * 8-bit arithmetic and no branches, so that it runs 16 (or 32) pixels per instruction once
 * vectorised. decode_reference is the same, plainly. */
static void read_bit(struct decode_ctx *d, int is_row, uint32_t k, const uint8_t *restrict pos,
                     const uint8_t *restrict neg, const uint8_t *restrict thr, size_t n)
{
    uint8_t *word = k < 8 ? d->work->word_hi[is_row] : d->work->word_lo[is_row];
    uint8_t *unc = k < 8 ? d->work->unclear_hi[is_row] : d->work->unclear_lo[is_row];
    /* a plane's first bit (0 or 8) writes it whole; the view's first, the columns' top bit
     * (columns come first in every layout and have at least one bit), the saturation plane too */
    if (!is_row && k == 0)
        read_bit_loop(word, unc, d->work->sat, pos, neg, thr, n, 1, 1);
    else if (k == 0 || k == 8)
        read_bit_loop(word, unc, d->work->sat, pos, neg, thr, n, 1, 0);
    else
        read_bit_loop(word, unc, d->work->sat, pos, neg, thr, n, 0, 0);
}

int decode_slot_free_before(struct decode_ctx *d, uint32_t pattern, uint32_t next)
{
    int is_row, paired, is_inverse;
    uint32_t k;
    uint8_t *own = decode_frame_slot(d, pattern), *slot = decode_frame_slot(d, next);
    if (own == NULL || slot == NULL || slot == own)
        return 0;
    if (pattern == GRAY_PATTERN_BLACK) /* begin_bits reads the white frame */
        return slot != d->white;
    /* decode_frame reads an inverse against its stripes' frame, kept in stage[0] */
    return pattern_bit(d, pattern, &is_row, &k, &paired, &is_inverse) != 0 || !is_inverse ||
           slot != d->work->stage[0];
}

int decode_frame(struct decode_ctx *d, uint32_t pattern, const uint8_t *grey)
{
    int is_row, paired, is_inverse;
    uint32_t k;
    if (pattern != d->next_pattern || pattern >= gray_layout_count(&d->layout))
        return -EINVAL;
    const size_t n = (size_t)d->params.width * d->params.height;
    uint8_t *slot = decode_frame_slot(d, pattern);
    if (grey != slot)
        memcpy(slot, grey, n);
    if (pattern == GRAY_PATTERN_BLACK)
        begin_bits(d, n);
    else if (pattern_bit(d, pattern, &is_row, &k, &paired, &is_inverse) == 0) {
        /* a bit without inverse is read against the mean of white and black */
        if (!paired)
            read_bit(d, is_row, k, d->work->stage[1], d->work->mean, d->work->mean_threshold, n);
        else if (is_inverse)
            read_bit(d, is_row, k, d->work->stage[0], d->work->stage[1], d->work->threshold, n);
    }
    d->next_pattern++;
    return 0;
}

/* Set bits of @p v, in a handful of operations (Hacker's Delight 5-2): the baseline x86-64 and
 * many ARM targets have no popcount instruction, and libgcc's call costs more. */
static unsigned count_bits(uint32_t v)
{
    v = v - ((v >> 1) & 0x55555555u);
    v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
    return (((v + (v >> 4)) & 0x0F0F0F0Fu) * 0x01010101u) >> 24;
}

/* Unclear bits that count. XOR-04: where the base bit is unclear (on the edge of its stripes),
 * every coarser pattern rides on that edge and is unclear with it; together they are one
 * unclear edge of the base, plus one more when any coarser bit is unclear too, which only the
 * neighbourhood can then resolve. */
static unsigned unclear_count(uint32_t unclear, uint32_t xor_mask)
{
    if (xor_mask == 0 || !(unclear & 2u))
        return count_bits(unclear);
    return count_bits(unclear & ~xor_mask) + ((unclear & xor_mask) != 0);
}

/* The reasons, in order of precedence; shared by the blocked decoder and the reference. A pixel
 * with too many unclear bits may still be resolved by its neighbourhood (resolve_unclear). */
static uint8_t classify(const struct scan_params *p, int white, int black, int both_saturated,
                        unsigned unclear_c, unsigned unclear_r, int out_of_range)
{
    int contrast = white - black;
    if (black == DECODE_SATURATED) /* no contrast to judge by */
        return SCAN_SATURATED;
    if (contrast <= (int)p->shadow_contrast_dn)
        return SCAN_SHADOW;
    if (contrast < (int)p->min_contrast_dn)
        return SCAN_DARK;
    /* One unclear bit per coordinate is a pixel on the edge between two columns (rows): adjacent
     * Gray codes differ in one bit, so either reading is one of the two. */
    if (unclear_c > p->max_ambiguous_bits || unclear_r > p->max_ambiguous_bits)
        return both_saturated ? SCAN_SATURATED : SCAN_LOW_CONTRAST;
    return out_of_range ? SCAN_INCONSISTENT : SCAN_VALID;
}

/* A Gray word (XOR-04 or plain) as its value: the base bit off the coarser ones again, then
 * Gray to binary by prefix XOR, in 16 bits. */
static inline uint16_t word_value(uint16_t g, uint16_t xor_mask)
{
    g ^= (uint16_t)(-((g >> 1) & 1u) & xor_mask);
    g ^= (uint16_t)(g >> 1);
    g ^= (uint16_t)(g >> 2);
    g ^= (uint16_t)(g >> 4);
    g ^= (uint16_t)(g >> 8);
    return g;
}

/* The per-pixel stage as a few plain loops over a block, each with no branch and in 16 bits, so
 * that GCC vectorises every one (8 or 16 pixels an instruction): written pixel by pixel with
 * classify it ran at 6.7 ns a pixel, half of the decoder's time at 3 MP (make bench). Each loop
 * is that code's step for every pixel of the block; decode_reference, the plain one, must agree.
 */

/* Byte planes to 16-bit words: (hi << lo_bits) | lo. */
static void block_words(uint16_t *restrict out, const uint8_t *restrict hi,
                        const uint8_t *restrict lo, unsigned lo_bits, size_t len)
{
    for (size_t i = 0; i < len; i++)
        out[i] = (uint16_t)((unsigned)(hi[i] << lo_bits) | lo[i]);
}

/* Gray words to their values in place (word_value). */
static void block_values(uint16_t *restrict v, uint16_t xor_mask, size_t len)
{
    for (size_t i = 0; i < len; i++)
        v[i] = word_value(v[i], xor_mask);
}

/* unclear_count of each word, branch free: where the base bit is unclear the XOR-04 bits count
 * as one more when any is unclear (with no XOR mask the sum is the plain count). */
static void block_unclear_counts(uint8_t *restrict count, const uint16_t *restrict unclear,
                                 uint16_t xor_mask, size_t len)
{
    for (size_t i = 0; i < len; i++) {
        uint16_t u = unclear[i];
        uint16_t m = (uint16_t)(xor_mask & -((u >> 1) & 1u)); /* the mask where it applies */
        uint16_t v = (uint16_t)(u & ~m);
        v = (uint16_t)(v - ((v >> 1) & 0x5555u)); /* Hacker's Delight 5-2, in 16 bits */
        v = (uint16_t)((v & 0x3333u) + ((v >> 2) & 0x3333u));
        v = (uint16_t)((v + (v >> 4)) & 0x0F0Fu);
        v = (uint16_t)((v + (v >> 8)) & 0x1Fu);
        count[i] = (uint8_t)(v + ((u & m) != 0));
    }
}

/* classify, as selects from the last rule to the first so that the first that holds wins.
 * Thresholds are clamped where the comparison no longer changes (contrast is -255..255, a
 * count at most 16), so that everything fits 16-bit lanes. */
static inline void block_reasons_loop(uint8_t *restrict reason, const struct decode_ctx *d,
                                      size_t start, const uint8_t *restrict count_c,
                                      const uint8_t *restrict count_r, size_t len, const int rows)
{
    const struct scan_params *p = &d->params;
    const int16_t shadow = (int16_t)(p->shadow_contrast_dn < 255u ? p->shadow_contrast_dn : 255u);
    const int16_t dark = (int16_t)(p->min_contrast_dn < 256u ? p->min_contrast_dn : 256u);
    const uint8_t most = (uint8_t)(p->max_ambiguous_bits < 255u ? p->max_ambiguous_bits : 255u);
    const uint16_t width = (uint16_t)d->proj_width, height = (uint16_t)d->proj_height;
    const uint8_t *restrict white = d->white + start, *restrict black = d->black + start;
    const uint8_t *restrict sat = d->work->sat + start;
    const uint16_t *restrict col = d->column_map + start, *restrict row = d->row_map + start;
    for (size_t i = 0; i < len; i++) {
        int16_t contrast = (int16_t)(white[i] - black[i]);
        uint8_t out = rows ? (col[i] >= width) | (row[i] >= height) : col[i] >= width;
        uint8_t r = out ? SCAN_INCONSISTENT : SCAN_VALID;
        uint8_t unclear = sat[i] ? SCAN_SATURATED : SCAN_LOW_CONTRAST;
        r = (rows ? (count_c[i] > most) | (count_r[i] > most) : count_c[i] > most) ? unclear : r;
        r = contrast < dark ? SCAN_DARK : r;
        r = contrast <= shadow ? SCAN_SHADOW : r;
        reason[i] = black[i] == DECODE_SATURATED ? SCAN_SATURATED : r;
    }
}

/* The loop with and without rows (a constant where it is inlined: with no rows coded their
 * planes are neither read nor written, and every pixel's row is as good as 0). */
static void block_reasons(uint8_t *restrict reason, const struct decode_ctx *d, size_t start,
                          const uint8_t *restrict count_c, const uint8_t *restrict count_r,
                          size_t len)
{
    if (d->layout.row_bits > 0)
        block_reasons_loop(reason, d, start, count_c, count_r, len, 1);
    else
        block_reasons_loop(reason, d, start, count_c, count_r, len, 0);
}

/* Pixels whose unclear bits are counted at a time: the counts live on the stack. */
#define DECODE_COUNT_CHUNK 256u

static void decode_block(struct decode_ctx *d, size_t start, size_t len, uint8_t *reason)
{
    const unsigned cols = d->layout.col_bits, rows = d->layout.row_bits;
    const unsigned lo_col = cols > 8 ? cols - 8 : 0, lo_row = rows > 8 ? rows - 8 : 0;
    block_words(d->column_map + start, d->work->word_hi[0] + start, d->work->word_lo[0] + start,
                lo_col, len);
    block_words(d->work->unclear_col + start, d->work->unclear_hi[0] + start,
                d->work->unclear_lo[0] + start, lo_col, len);
    block_values(d->column_map + start, (uint16_t)d->xor_col, len);
    if (rows > 0) {
        block_words(d->row_map + start, d->work->word_hi[1] + start, d->work->word_lo[1] + start,
                    lo_row, len);
        block_words(d->work->unclear_row + start, d->work->unclear_hi[1] + start,
                    d->work->unclear_lo[1] + start, lo_row, len);
        block_values(d->row_map + start, (uint16_t)d->xor_row, len);
    }
    for (size_t at = start; at < start + len; at += DECODE_COUNT_CHUNK) {
        size_t n = start + len - at < DECODE_COUNT_CHUNK ? start + len - at : DECODE_COUNT_CHUNK;
        uint8_t count_c[DECODE_COUNT_CHUNK], count_r[DECODE_COUNT_CHUNK];
        block_unclear_counts(count_c, d->work->unclear_col + at, (uint16_t)d->xor_col, n);
        if (rows > 0)
            block_unclear_counts(count_r, d->work->unclear_row + at, (uint16_t)d->xor_row, n);
        block_reasons(reason + at, d, at, count_c, count_r, n);
    }
}

/* Part @p k of @p parts of the pixels, whole blocks, with the accumulators of its own. */
struct pixel_parts {
    struct decode_ctx *d;
    uint8_t *reason;
    size_t pixels;
    unsigned parts;
};

static void decode_part(void *arg, unsigned k)
{
    const struct pixel_parts *p = arg;
    size_t blocks = (p->pixels + DECODE_BLOCK - 1u) / DECODE_BLOCK;
    for (size_t b = blocks * k / p->parts; b < blocks * (k + 1u) / p->parts; b++) {
        size_t start = b * DECODE_BLOCK, left = p->pixels - start;
        decode_block(p->d, start, left < DECODE_BLOCK ? left : DECODE_BLOCK, p->reason);
    }
}

int decode_pixels(struct decode_ctx *d, const struct hal_thread *threads, uint8_t *reason,
                  struct decode_maps *maps)
{
    if (d->next_pattern != gray_layout_count(&d->layout))
        return -EINVAL;
    /* every pixel on its own: the same maps however the pixels are split */
    struct pixel_parts p = {d, reason, (size_t)d->params.width * d->params.height,
                            hal_thread_parts(threads, HAL_MAX_THREADS)};
    hal_thread_run(threads, p.parts, decode_part, &p);
    maps->column = d->column_map;
    maps->row = d->layout.row_bits > 0 ? d->row_map : NULL;
    maps->reason = reason;
    maps->width = d->params.width;
    maps->height = d->params.height;
    return 0;
}

/* ---- the neighbourhood stages ---- */

#define RESOLVE_RADIUS 2 /* the neighbourhood an unclear pixel is resolved in: 5 x 5 */
#define RESOLVE_MAX (2 * RESOLVE_RADIUS + 1) * (2 * RESOLVE_RADIUS + 1)
/* A reading (a neighbour) agrees with the neighbourhood's plane within this many columns: the
 * width of a stripe edge, where either of two adjacent columns is right. */
#define RESOLVE_FIT_COLUMNS 1.5

static int within(int a, int b, uint32_t jump)
{
    return a - b <= (int)jump && b - a <= (int)jump;
}

/* The column (row) the decoded pixels around (x, y) predict for it. The stripes run across
 * the window (about a column per pixel at the camera's limit), so not their median: a plane
 * c = a + b dx + e dy fitted to the pixels the per-pixel stage left valid, after dropping those
 * far from their median (a wrong bit), and trusted when at least min_consistent_neighbours lie
 * within RESOLVE_FIT_COLUMNS of it. @retval 1 found (a, in *ref) @retval 0 no agreement */
static int neighbourhood_code(const struct decode_ctx *d, const uint8_t *reason,
                              const uint16_t *map, uint32_t x, uint32_t y, double *ref)
{
    const uint32_t w = d->params.width, h = d->params.height;
    int v[RESOLVE_MAX], sorted[RESOLVE_MAX], ox[RESOLVE_MAX], oy[RESOLVE_MAX];
    uint32_t n = 0;
    for (int dy = -RESOLVE_RADIUS; dy <= RESOLVE_RADIUS; dy++)
        for (int dx = -RESOLVE_RADIUS; dx <= RESOLVE_RADIUS; dx++) {
            long nx = (long)x + dx, ny = (long)y + dy;
            if (nx < 0 || ny < 0 || nx >= (long)w || ny >= (long)h)
                continue;
            uint8_t r = reason[(size_t)ny * w + (size_t)nx];
            if (r == SCAN_SHADOW)
                return 0; /* beside a silhouette or a shadow: a blurred pixel mixes two surfaces */
            if (r != SCAN_VALID)
                continue;
            int c = map[(size_t)ny * w + (size_t)nx];
            v[n] = c, ox[n] = dx, oy[n] = dy;
            uint32_t k = n++; /* insertion sort: a handful of values */
            for (; k > 0 && sorted[k - 1] > c; k--)
                sorted[k] = sorted[k - 1];
            sorted[k] = c;
        }
    if (n < d->params.min_consistent_neighbours || n < 3)
        return 0;
    int median = sorted[n / 2];
    double a[9] = {0}, b[3] = {0}, coef[3]; /* normal equations of the plane */
    for (uint32_t k = 0; k < n; k++) {
        if (!within(v[k], median, 2 * RESOLVE_RADIUS))
            continue;
        double row[3] = {1.0, ox[k], oy[k]};
        for (int i = 0; i < 3; i++) {
            for (int j = 0; j < 3; j++)
                a[3 * i + j] += row[i] * row[j];
            b[i] += row[i] * v[k];
        }
    }
    /* The pixels on one line fix no plane (lsq_solve would leave that slope 0 and go on). */
    double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
                 a[2] * (a[3] * a[7] - a[4] * a[6]);
    if (fabs(det) < 1e-9 || lsq_solve(3, a, b, coef) != 0)
        return 0;
    uint32_t agree = 0;
    for (uint32_t k = 0; k < n; k++)
        agree += fabs(coef[0] + coef[1] * ox[k] + coef[2] * oy[k] - v[k]) <= RESOLVE_FIT_COLUMNS;
    *ref = coef[0];
    return agree >= d->params.min_consistent_neighbours;
}

/* Of the values an unclear pixel can have, the one nearest @p ref: the values within
 * RESOLVE_FIT_COLUMNS of it whose projected word matches what the pixel read on every clear
 * pattern (an unclear bit lies on a stripe edge and may read either way). The word the pixel
 * read is the word of its plain value (value and word are one to one).
 * @retval 1 found (in *value) @retval 0 none */
static int nearest_reading(uint32_t code, uint32_t bits, uint16_t plain, uint16_t unclear,
                           double ref, uint32_t limit, uint16_t *value)
{
    const uint32_t read = gray_code_word(code, bits, plain);
    long lo = (long)ceil(ref - RESOLVE_FIT_COLUMNS), hi = (long)floor(ref + RESOLVE_FIT_COLUMNS);
    int best = -1;
    for (long c = lo < 0 ? 0 : lo; c <= hi && c < (long)limit; c++)
        if (((gray_code_word(code, bits, (uint32_t)c) ^ read) & ~(uint32_t)unclear) == 0 &&
            (best < 0 || fabs((double)c - ref) < fabs((double)best - ref)))
            best = (int)c;
    if (best < 0)
        return 0;
    *value = (uint16_t)best;
    return 1;
}

/* A verdict of resolve_unclear in the scratch plane: valid, its reading replaced. */
#define RESOLVE_CORRECTED SCAN_REASON_COUNT

/* Rows of a neighbourhood stage split into parts (every pixel's verdict is its own: the same
 * maps however many). */
struct row_parts {
    struct decode_ctx *d;
    uint8_t *reason;
    unsigned parts;
};

static void resolve_rows(void *arg, unsigned k)
{
    const struct row_parts *p = arg;
    struct decode_ctx *d = p->d;
    const uint8_t *reason = p->reason;
    const uint32_t w = d->params.width, h = d->params.height;
    const uint32_t max_unclear = d->params.max_unclear_bits;
    const int rows = d->layout.row_bits > 0;
    for (uint32_t y = h * k / p->parts; y < h * (k + 1u) / p->parts; y++) {
        for (uint32_t x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            uint8_t r = reason[i];
            d->work->scratch[i] = r;
            int pending = r == SCAN_LOW_CONTRAST || r == SCAN_SATURATED || r == SCAN_INCONSISTENT;
            uint16_t unclear_row = rows ? d->work->unclear_row[i] : 0; /* no rows: no row planes */
            if ((!pending && r != SCAN_VALID) ||
                (d->work->unclear_col[i] == 0 && unclear_row == 0) ||
                unclear_count(d->work->unclear_col[i], d->xor_col) > max_unclear ||
                unclear_count(unclear_row, d->xor_row) > max_unclear)
                continue;
            double ref_col, ref_row = 0.0;
            uint16_t col, row = 0;
            if (!neighbourhood_code(d, reason, d->column_map, x, y, &ref_col) ||
                !nearest_reading(d->layout.code, d->layout.col_bits, d->column_map[i],
                                 d->work->unclear_col[i], ref_col, d->proj_width, &col) ||
                (rows && (!neighbourhood_code(d, reason, d->row_map, x, y, &ref_row) ||
                          !nearest_reading(d->layout.code, d->layout.row_bits, d->row_map[i],
                                           unclear_row, ref_row, d->proj_height, &row))))
                continue;
            if (pending) { /* not a reference of this pass: its maps can change now */
                d->column_map[i] = col;
                if (rows)
                    d->row_map[i] = row;
                d->work->scratch[i] = SCAN_VALID;
            } else if (col != d->column_map[i] || (rows && row != d->row_map[i])) {
                d->work->unclear_col[i] = col;
                if (rows)
                    d->work->unclear_row[i] = row;
                d->work->scratch[i] = RESOLVE_CORRECTED;
            }
        }
    }
}

/* The pixels of part @p k of the rows: [*i0, *i1). */
static void part_pixels(const struct row_parts *p, unsigned k, size_t *i0, size_t *i1)
{
    const size_t w = p->d->params.width, h = p->d->params.height;
    *i0 = w * (h * k / p->parts);
    *i1 = w * (h * (k + 1u) / p->parts);
}

/* Part @p k of the rows once every part has read them: the verdicts made the reasons. */
static void verdicts_apply(void *arg, unsigned k)
{
    const struct row_parts *p = arg;
    size_t i0, i1;
    part_pixels(p, k, &i0, &i1);
    memcpy(p->reason + i0, p->d->work->scratch + i0, i1 - i0);
}

/* Part @p k of the rows once every part has read them: the corrections applied, then the
 * verdicts made the reasons. */
static void resolve_apply(void *arg, unsigned k)
{
    const struct row_parts *p = arg;
    struct decode_ctx *d = p->d;
    size_t i0, i1;
    part_pixels(p, k, &i0, &i1);
    const int rows = d->layout.row_bits > 0;
    for (size_t i = i0; i < i1; i++) {
        if (d->work->scratch[i] == RESOLVE_CORRECTED) {
            d->column_map[i] = d->work->unclear_col[i];
            if (rows)
                d->row_map[i] = d->work->unclear_row[i];
            d->work->scratch[i] = SCAN_VALID;
        }
    }
    verdicts_apply(arg, k);
}

/* A pixel with unclear bits takes, of its possible readings, the one its decoded neighbourhood
 * predicts: one with more than max_ambiguous_bits (or decoding outside the projector) becomes
 * valid so; a valid one whose unclear bit read the wrong way (noise, not an edge) is corrected.
 * Verdicts go to the scratch plane and corrections wait in the unclear maps (not needed after this)
 * until the pass ends, so that what this pass changes is not the reference of others. */
static void resolve_unclear(struct decode_ctx *d, const struct hal_thread *threads, uint8_t *reason)
{
    struct row_parts p = {d, reason, hal_thread_parts(threads, 64)};
    hal_thread_run(threads, p.parts, resolve_rows, &p);
    hal_thread_run(threads, p.parts, resolve_apply, &p);
}

static int codes_agree(const struct decode_ctx *d, const uint8_t *reason, size_t a, size_t b)
{
    if (reason[b] != SCAN_VALID)
        return 0;
    return within(d->column_map[a], d->column_map[b], d->params.max_column_jump) &&
           (d->layout.row_bits == 0 ||
            within(d->row_map[a], d->row_map[b], d->params.max_column_jump));
}

static void check_rows(void *arg, unsigned k)
{
    const struct row_parts *p = arg;
    struct decode_ctx *d = p->d;
    const uint8_t *reason = p->reason;
    const uint32_t w = d->params.width, h = d->params.height;
    for (uint32_t y = h * k / p->parts; y < h * (k + 1u) / p->parts; y++) {
        for (uint32_t x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            d->work->scratch[i] = reason[i];
            if (reason[i] != SCAN_VALID)
                continue;
            uint32_t agree = 0, valid = 0;
            for (int dy = -1; dy <= 1; dy++) {
                for (int dx = -1; dx <= 1; dx++) {
                    int nx = (int)x + dx, ny = (int)y + dy;
                    if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= (int)w || ny >= (int)h)
                        continue;
                    size_t j = (size_t)ny * w + (size_t)nx;
                    valid += reason[j] == SCAN_VALID;
                    agree += (uint32_t)codes_agree(d, reason, i, j);
                }
            }
            if (agree >= d->params.min_consistent_neighbours)
                continue;
            double ref_col, ref_row;
            if (valid - agree > agree || agree == 0 ||
                !neighbourhood_code(d, reason, d->column_map, x, y, &ref_col) ||
                fabs(d->column_map[i] - ref_col) > RESOLVE_FIT_COLUMNS ||
                (d->layout.row_bits > 0 &&
                 (!neighbourhood_code(d, reason, d->row_map, x, y, &ref_row) ||
                  fabs(d->row_map[i] - ref_row) > RESOLVE_FIT_COLUMNS)))
                d->work->scratch[i] = SCAN_INCONSISTENT;
        }
    }
}

/* A wrong bit makes a lone jump: a pixel is inconsistent when more of its valid neighbours
 * disagree with it than agree, or when fewer than min_consistent_neighbours agree and none of
 * its 5 x 5 neighbourhood backs it. A pixel with only a few valid neighbours, all agreeing (on
 * a thin part, beside a shadow), is kept: alone is not wrong. Columns and, when coded, rows. */
static void check_neighbours(struct decode_ctx *d, const struct hal_thread *threads,
                             uint8_t *reason)
{
    struct row_parts p = {d, reason, hal_thread_parts(threads, 64)};
    hal_thread_run(threads, p.parts, check_rows, &p);
    hal_thread_run(threads, p.parts, verdicts_apply, &p);
}

int decode_finish(struct decode_ctx *d, const struct hal_thread *threads, uint8_t *reason,
                  struct decode_maps *maps)
{
    int rc = decode_pixels(d, threads, reason, maps);
    if (rc == 0) {
        resolve_unclear(d, threads, reason);
        check_neighbours(d, threads, reason);
    }
    return rc;
}

/* ---- the plain reference: one pixel at a time, every frame ---- */

/* @p t: the threshold of a bit with its inverse, @p tm of one against the mean */
static uint16_t reference_bits(const uint8_t *const *frames, const struct gray_layout *l,
                               int is_row, size_t i, int t, int tm, unsigned *unclear,
                               int *both_saturated)
{
    uint32_t word = 0, bits = is_row ? l->row_bits : l->col_bits;
    int mean = (frames[GRAY_PATTERN_WHITE][i] + frames[GRAY_PATTERN_BLACK][i] + 1) / 2;
    *unclear = 0;
    for (uint32_t k = 0; k < bits; k++) {
        uint32_t stripes;
        int32_t inverse;
        gray_layout_bit(l, is_row, k, &stripes, &inverse);
        int a = frames[stripes][i], b = inverse >= 0 ? frames[inverse][i] : mean;
        int limit = inverse >= 0 ? t : tm;
        word = (word << 1) | (a > b ? 1u : 0u);
        *unclear = (*unclear << 1) | (a - b <= limit && b - a <= limit);
        *both_saturated |= a == DECODE_SATURATED && b == DECODE_SATURATED;
    }
    return (uint16_t)gray_code_value(l->code, bits, word);
}

void decode_reference(const struct scan_params *p, const struct gray_layout *l, uint32_t proj_width,
                      uint32_t proj_height, const uint8_t *const *frames, size_t n,
                      uint16_t *column, uint16_t *row, uint8_t *reason)
{
    for (size_t i = 0; i < n; i++) {
        unsigned unclear_c = 0, unclear_r = 0;
        int white = frames[GRAY_PATTERN_WHITE][i], black = frames[GRAY_PATTERN_BLACK][i];
        uint32_t contrast = (uint32_t)(white > black ? white - black : 0);
        int t = (int)decode_bit_threshold(p, contrast),
            tm = (int)decode_mean_threshold(p, contrast);
        int sat = 0;
        column[i] = reference_bits(frames, l, 0, i, t, tm, &unclear_c, &sat);
        uint16_t r = 0;
        if (l->row_bits > 0)
            r = reference_bits(frames, l, 1, i, t, tm, &unclear_r, &sat);
        if (row != NULL)
            row[i] = r;
        int out = column[i] >= proj_width || (l->row_bits > 0 && r >= proj_height);
        reason[i] =
            classify(p, white, black, sat,
                     unclear_count(unclear_c, gray_code_xor_mask(l->code, l->col_bits)),
                     unclear_count(unclear_r, gray_code_xor_mask(l->code, l->row_bits)), out);
    }
}
