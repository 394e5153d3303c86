/* Gray-code decoding in static buffers: one pass per frame, so frames need not be kept. */
#include "decode.h"

#include "gray.h"

#include <errno.h>
#include <string.h>

static uint16_t column_map[HAL_MAX_PIXELS]; /* Gray code while decoding, column afterwards */
static uint8_t reason_map[HAL_MAX_PIXELS];
static uint8_t grey_white[HAL_MAX_PIXELS]; /* white frame, then scratch for the positive frame */
/* While decoding: bits within the noise per pixel; in decode_finish: neighbour agreement. */
static uint8_t scratch[HAL_MAX_PIXELS];

static struct {
    struct scan_params params;
    uint32_t bits;
    uint32_t proj_width;
    uint32_t next_pattern;
    struct decode_maps maps;
} dec;

const char *scan_reason_name(unsigned reason)
{
    static const char *const names[SCAN_REASON_COUNT] = {
        "valid", "shadow", "dark", "low_contrast", "saturated", "inconsistent"};
    return reason < SCAN_REASON_COUNT ? names[reason] : "unknown";
}

int decode_begin(const struct scan_params *params, uint32_t proj_width)
{
    if (params->width == 0 || params->height == 0 || params->width > HAL_MAX_WIDTH ||
        params->height > HAL_MAX_HEIGHT || proj_width == 0 || proj_width > HAL_MAX_PROJECTOR_WIDTH)
        return -EINVAL;
    dec.params = *params;
    dec.bits = gray_bits_for_width(proj_width);
    dec.proj_width = proj_width;
    dec.next_pattern = 0;
    dec.maps.column = column_map;
    dec.maps.reason = reason_map;
    dec.maps.width = params->width;
    dec.maps.height = params->height;
    size_t n = (size_t)params->width * params->height;
    memset(column_map, 0, n * sizeof(column_map[0]));
    memset(reason_map, SCAN_VALID, n);
    memset(scratch, 0, n);
    return 0;
}

void decode_rgb_to_grey(const uint8_t *rgb, uint8_t *grey, size_t n, uint32_t saturation_dn)
{
    for (size_t i = 0; i < n; i++, rgb += 3) {
        int saturated = rgb[0] >= saturation_dn || rgb[1] >= saturation_dn || rgb[2] >= saturation_dn;
        uint32_t luma = (77u * rgb[0] + 150u * rgb[1] + 29u * rgb[2]) >> 8; /* BT.601 weights */
        grey[i] = saturated ? DECODE_SATURATED : (uint8_t)(luma < 254u ? luma : 254u);
    }
}

/* Reject a pixel, keeping the first reason found: later frames do not overwrite it. */
static void reject(size_t i, enum scan_reason why)
{
    if (reason_map[i] == SCAN_VALID)
        reason_map[i] = (uint8_t)why;
}

/* Keep a frame that a later frame is compared with: the white frame (against black), then each
 * bit's positive pattern (against its inverse), which reuses the buffer once white is done. */
static void take_reference(const uint8_t *grey, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        grey_white[i] = grey[i];
        if (grey[i] == DECODE_SATURATED)
            reject(i, SCAN_SATURATED);
    }
}

static void take_black(const uint8_t *grey, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        int contrast = (int)grey_white[i] - (int)grey[i];
        if (grey[i] == DECODE_SATURATED)
            reject(i, SCAN_SATURATED);
        else if (contrast <= (int)dec.params.shadow_contrast_dn)
            reject(i, SCAN_SHADOW);
        else if (contrast < (int)dec.params.min_contrast_dn)
            reject(i, SCAN_DARK);
    }
}

/* A bit whose pattern and inverse are within the noise is ambiguous. Where a pixel straddles the
 * edge between two projector columns exactly one bit is ambiguous (adjacent Gray codes differ in
 * one bit), and either reading gives one of the two columns: harmless. Two or more ambiguous bits
 * mean the signal itself is too weak to trust. */
static void take_inverse(const uint8_t *grey, size_t n)
{
    const int min_diff = (int)dec.params.min_bit_diff_dn;
    for (size_t i = 0; i < n; i++) {
        int diff = (int)grey_white[i] - (int)grey[i];
        column_map[i] = (uint16_t)((column_map[i] << 1) | (diff > 0 ? 1u : 0u));
        if (grey[i] == DECODE_SATURATED)
            reject(i, SCAN_SATURATED);
        else if (diff <= min_diff && diff >= -min_diff &&
                 ++scratch[i] > dec.params.max_ambiguous_bits)
            reject(i, SCAN_LOW_CONTRAST);
    }
}

int decode_frame(uint32_t pattern_index, const uint8_t *grey)
{
    if (pattern_index != dec.next_pattern || pattern_index >= gray_pattern_count(dec.bits))
        return -EINVAL;
    size_t n = (size_t)dec.params.width * dec.params.height;
    if (pattern_index == GRAY_PATTERN_BLACK)
        take_black(grey, n);
    else if (pattern_index == GRAY_PATTERN_WHITE ||
             (pattern_index - GRAY_PATTERN_FIRST_BIT) % 2u == 0u)
        take_reference(grey, n);
    else
        take_inverse(grey, n);
    dec.next_pattern++;
    return 0;
}

static int columns_agree(size_t a, size_t b)
{
    if (reason_map[b] != SCAN_VALID)
        return 0;
    int d = (int)column_map[a] - (int)column_map[b];
    return d <= (int)dec.params.max_column_jump && d >= -(int)dec.params.max_column_jump;
}

/* A correct decode agrees with most of its neighbours; a wrong bit makes a lone jump. */
static void check_neighbours(void)
{
    const uint32_t w = dec.params.width, h = dec.params.height;
    for (uint32_t y = 0; y < h; y++) {
        for (uint32_t x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            scratch[i] = 1;
            if (reason_map[i] != SCAN_VALID)
                continue;
            uint32_t agree = 0;
            for (int dy = -1; dy <= 1; dy++) {
                for (int dx = -1; dx <= 1; dx++) {
                    int nx = (int)x + dx, ny = (int)y + dy;
                    if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= (int)w || ny >= (int)h)
                        continue;
                    agree += (uint32_t)columns_agree(i, (size_t)ny * w + (size_t)nx);
                }
            }
            scratch[i] = agree >= dec.params.min_consistent_neighbours;
        }
    }
    size_t n = (size_t)w * h;
    for (size_t i = 0; i < n; i++)
        if (!scratch[i])
            reject(i, SCAN_INCONSISTENT);
}

int decode_finish(void)
{
    if (dec.next_pattern != gray_pattern_count(dec.bits))
        return -EINVAL;
    size_t n = (size_t)dec.params.width * dec.params.height;
    for (size_t i = 0; i < n; i++) {
        uint32_t col = gray_decode(column_map[i]);
        column_map[i] = (uint16_t)col;
        if (col >= dec.proj_width)
            reject(i, SCAN_INCONSISTENT);
    }
    check_neighbours();
    return 0;
}

const struct decode_maps *decode_get_maps(void)
{
    return &dec.maps;
}
