/* Gray-code decoding of a whole view from its kept frames, block by block. */
#include "decode.h"

#include <errno.h>
#include <string.h>

/* One block of pixels: its accumulators stay in the first-level cache while every frame streams
 * through once. */
#define DECODE_BLOCK 4096u

static uint8_t frame_store[DECODE_MAX_PATTERNS][HAL_MAX_PIXELS];
static uint16_t column_map[HAL_MAX_PIXELS];
static uint16_t row_map[HAL_MAX_PIXELS];
static uint8_t consistent[HAL_MAX_PIXELS];

static struct {
    struct scan_params params;
    struct gray_layout layout;
    uint32_t proj_width, proj_height;
    uint32_t next_pattern;
} dec;

const char *scan_reason_name(unsigned reason)
{
    static const char *const names[SCAN_REASON_COUNT] = {
        "valid", "shadow", "dark", "low_contrast", "saturated", "inconsistent"};
    return reason < SCAN_REASON_COUNT ? names[reason] : "unknown";
}

void decode_rgb_to_grey(const uint8_t *rgb, uint8_t *grey, size_t n, uint32_t saturation_dn)
{
    for (size_t i = 0; i < n; i++, rgb += 3) {
        int saturated = rgb[0] >= saturation_dn || rgb[1] >= saturation_dn || rgb[2] >= saturation_dn;
        uint32_t luma = (77u * rgb[0] + 150u * rgb[1] + 29u * rgb[2]) >> 8; /* BT.601 weights */
        grey[i] = saturated ? DECODE_SATURATED : (uint8_t)(luma < 254u ? luma : 254u);
    }
}

int decode_begin(const struct scan_params *params, const struct gray_layout *layout,
                 uint32_t proj_width, uint32_t proj_height)
{
    if (params->width == 0 || params->height == 0 || params->width > HAL_MAX_WIDTH ||
        params->height > HAL_MAX_HEIGHT || layout->col_bits == 0 || layout->col_bits > 16 ||
        layout->row_bits > 16 || gray_layout_count(layout) > DECODE_MAX_PATTERNS)
        return -EINVAL;
    dec.params = *params;
    dec.layout = *layout;
    dec.proj_width = proj_width;
    dec.proj_height = proj_height;
    dec.next_pattern = 0;
    return 0;
}

uint8_t *decode_frame_slot(uint32_t pattern)
{
    return pattern < gray_layout_count(&dec.layout) ? frame_store[pattern] : NULL;
}

int decode_frame(uint32_t pattern, const uint8_t *grey)
{
    if (pattern != dec.next_pattern || pattern >= gray_layout_count(&dec.layout))
        return -EINVAL;
    if (grey != frame_store[pattern])
        memcpy(frame_store[pattern], grey, (size_t)dec.params.width * dec.params.height);
    dec.next_pattern++;
    return 0;
}

/* The bits of one coordinate for a block: Gray code, ambiguous-bit count, brightest value.
 * Only 8-bit arithmetic in the loop over pixels, so that it runs 16 (or 32) pixels per
 * instruction once vectorised: the code is gathered in two byte planes (the first 8 bits, then
 * the rest), |I - I_inverse| comes from two saturating subtractions, and saturation is the
 * maximum over the frames reaching DECODE_SATURATED. decode_reference is the same, plainly. */
static void accumulate(uint32_t first, uint32_t bits, size_t start, size_t len, uint16_t *code,
                       uint8_t *ambiguous, uint8_t *brightest)
{
    static uint8_t plane_hi[DECODE_BLOCK], plane_lo[DECODE_BLOCK];
    const uint8_t t = (uint8_t)(dec.params.min_bit_diff_dn > 254 ? 254 : dec.params.min_bit_diff_dn);
    memset(plane_hi, 0, len);
    memset(plane_lo, 0, len);
    memset(ambiguous, 0, len);
    for (uint32_t k = 0; k < bits; k++) {
        const uint8_t *restrict pos = frame_store[first + 2u * k] + start;
        const uint8_t *restrict neg = frame_store[first + 2u * k + 1u] + start;
        uint8_t *restrict plane = k < 8 ? plane_hi : plane_lo;
        uint8_t *restrict amb = ambiguous, *restrict mx = brightest;
        for (size_t i = 0; i < len; i++) {
            uint8_t a = pos[i], b = neg[i];
            uint8_t up = (uint8_t)(a > b ? a - b : 0), down = (uint8_t)(b > a ? b - a : 0);
            plane[i] = (uint8_t)((plane[i] << 1) | (up != 0));
            amb[i] = (uint8_t)(amb[i] + ((up | down) <= t));
            uint8_t m = a > b ? a : b;
            mx[i] = mx[i] > m ? mx[i] : m;
        }
    }
    const uint32_t lo_bits = bits > 8 ? bits - 8 : 0;
    for (size_t i = 0; i < len; i++) {
        uint16_t g = (uint16_t)(((unsigned)plane_hi[i] << lo_bits) | plane_lo[i]);
        g ^= (uint16_t)(g >> 1); /* Gray to binary: prefix XOR */
        g ^= (uint16_t)(g >> 2);
        g ^= (uint16_t)(g >> 4);
        g ^= (uint16_t)(g >> 8);
        code[i] = g;
    }
}

/* The reasons, in order of precedence; shared by the blocked decoder and the reference. */
static uint8_t classify(const struct scan_params *p, int white, int black, int saturated,
                        unsigned amb_col, unsigned amb_row, int out_of_range)
{
    int contrast = white - black;
    if (saturated)
        return SCAN_SATURATED;
    if (contrast <= (int)p->shadow_contrast_dn)
        return SCAN_SHADOW;
    if (contrast < (int)p->min_contrast_dn)
        return SCAN_DARK;
    /* One ambiguous bit per coordinate is a pixel on the edge between two columns (rows): adjacent
     * Gray codes differ in one bit, so either reading is one of the two. More is weak signal. */
    if (amb_col > p->max_ambiguous_bits || amb_row > p->max_ambiguous_bits)
        return SCAN_LOW_CONTRAST;
    return out_of_range ? SCAN_INCONSISTENT : SCAN_VALID;
}

static void decode_block(size_t start, size_t len, uint8_t *reason)
{
    static uint16_t code_col[DECODE_BLOCK], code_row[DECODE_BLOCK];
    static uint8_t amb_col[DECODE_BLOCK], amb_row[DECODE_BLOCK], sat[DECODE_BLOCK];
    const uint8_t *white = frame_store[GRAY_PATTERN_WHITE] + start;
    const uint8_t *black = frame_store[GRAY_PATTERN_BLACK] + start;
    const struct gray_layout *l = &dec.layout;
    for (size_t i = 0; i < len; i++) /* brightest so far; == DECODE_SATURATED means saturated */
        sat[i] = white[i] > black[i] ? white[i] : black[i];
    accumulate(GRAY_PATTERN_FIRST_BIT, l->col_bits, start, len, code_col, amb_col, sat);
    if (l->row_bits > 0)
        accumulate(GRAY_PATTERN_FIRST_BIT + 2u * l->col_bits, l->row_bits, start, len, code_row,
                   amb_row, sat);
    else
        memset(amb_row, 0, len);
    for (size_t i = 0; i < len; i++) {
        int out = code_col[i] >= dec.proj_width ||
                  (l->row_bits > 0 && code_row[i] >= dec.proj_height);
        reason[start + i] = classify(&dec.params, white[i], black[i],
                                         sat[i] == DECODE_SATURATED, amb_col[i], amb_row[i], out);
        column_map[start + i] = code_col[i];
        row_map[start + i] = l->row_bits > 0 ? code_row[i] : 0;
    }
}

int decode_pixels(uint8_t *reason, struct decode_maps *maps)
{
    if (dec.next_pattern != gray_layout_count(&dec.layout))
        return -EINVAL;
    size_t n = (size_t)dec.params.width * dec.params.height;
    for (size_t start = 0; start < n; start += DECODE_BLOCK)
        decode_block(start, n - start < DECODE_BLOCK ? n - start : DECODE_BLOCK, reason);
    maps->column = column_map;
    maps->row = dec.layout.row_bits > 0 ? row_map : NULL;
    maps->reason = reason;
    maps->width = dec.params.width;
    maps->height = dec.params.height;
    return 0;
}

static int columns_agree(const uint8_t *reason, size_t a, size_t b)
{
    if (reason[b] != SCAN_VALID)
        return 0;
    int d = (int)column_map[a] - (int)column_map[b];
    return d <= (int)dec.params.max_column_jump && d >= -(int)dec.params.max_column_jump;
}

/* A correct decode agrees with most of its neighbours; a wrong bit makes a lone jump. */
static void check_neighbours(uint8_t *reason)
{
    const uint32_t w = dec.params.width, h = dec.params.height;
    for (uint32_t y = 0; y < h; y++) {
        for (uint32_t x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            consistent[i] = 1;
            if (reason[i] != SCAN_VALID)
                continue;
            uint32_t agree = 0;
            for (int dy = -1; dy <= 1; dy++) {
                for (int dx = -1; dx <= 1; dx++) {
                    int nx = (int)x + dx, ny = (int)y + dy;
                    if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= (int)w || ny >= (int)h)
                        continue;
                    agree += (uint32_t)columns_agree(reason, i, (size_t)ny * w + (size_t)nx);
                }
            }
            consistent[i] = agree >= dec.params.min_consistent_neighbours;
        }
    }
    size_t n = (size_t)w * h;
    for (size_t i = 0; i < n; i++)
        if (!consistent[i] && reason[i] == SCAN_VALID)
            reason[i] = SCAN_INCONSISTENT;
}

int decode_finish(uint8_t *reason, struct decode_maps *maps)
{
    int rc = decode_pixels(reason, maps);
    if (rc == 0)
        check_neighbours(reason);
    return rc;
}

/* ---- the plain reference: one pixel at a time, every frame ---- */

static uint16_t reference_bits(const uint8_t *const *frames, uint32_t first, uint32_t bits,
                               size_t i, int t, unsigned *ambiguous, int *saturated)
{
    uint32_t gray = 0;
    *ambiguous = 0;
    for (uint32_t k = 0; k < bits; k++) {
        int a = frames[first + 2u * k][i], b = frames[first + 2u * k + 1u][i];
        gray = (gray << 1) | (a > b ? 1u : 0u);
        *ambiguous += a - b <= t && b - a <= t;
        *saturated |= a == DECODE_SATURATED || b == DECODE_SATURATED;
    }
    return (uint16_t)gray_decode(gray);
}

void decode_reference(const struct scan_params *p, const struct gray_layout *l,
                      uint32_t proj_width, uint32_t proj_height, const uint8_t *const *frames,
                      size_t n, uint16_t *column, uint16_t *row, uint8_t *reason)
{
    const int t = (int)p->min_bit_diff_dn;
    for (size_t i = 0; i < n; i++) {
        unsigned amb_col = 0, amb_row = 0;
        int white = frames[GRAY_PATTERN_WHITE][i], black = frames[GRAY_PATTERN_BLACK][i];
        int sat = white == DECODE_SATURATED || black == DECODE_SATURATED;
        column[i] = reference_bits(frames, GRAY_PATTERN_FIRST_BIT, l->col_bits, i, t, &amb_col,
                                   &sat);
        uint16_t r = 0;
        if (l->row_bits > 0)
            r = reference_bits(frames, GRAY_PATTERN_FIRST_BIT + 2u * l->col_bits, l->row_bits, i,
                               t, &amb_row, &sat);
        if (row != NULL)
            row[i] = r;
        int out = column[i] >= proj_width || (l->row_bits > 0 && r >= proj_height);
        reason[i] = classify(p, white, black, sat, amb_col, amb_row, out);
    }
}
