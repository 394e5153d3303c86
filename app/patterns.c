/* The projector's stored Gray-code sequence written as PNG files (scanner patterns). */
#include "patterns.h"

#include "gray.h"
#include "image_io.h"
#include "scan.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* What pattern @p index of @p l shows, in words. */
static void describe(const struct gray_layout *l, uint32_t index, char *out, size_t len)
{
    if (index == GRAY_PATTERN_WHITE) {
        snprintf(out, len, "white");
        return;
    }
    if (index == GRAY_PATTERN_BLACK) {
        snprintf(out, len, "black");
        return;
    }
    int row, inverse;
    uint32_t bit; /* most significant first */
    if (gray_layout_pattern(l, index, &row, &bit, &inverse) != 0) {
        snprintf(out, len, "none");
        return;
    }
    uint32_t bits = row ? l->row_bits : l->col_bits;
    uint32_t position = bits - 1u - bit; /* of the bit in the word, 0 the finest */
    int rides = (gray_code_xor_mask(l->code, bits) >> position) & 1u;
    char rides_on[24] = ""; /* XOR-04: the base it rides on */
    if (rides)
        snprintf(rides_on, sizeof(rides_on), " XOR bit %u", bits - 1u);
    snprintf(out, len, "%s bit %u of %u%s%s%s", row ? "row" : "column", bit + 1u, bits,
             bit == 0           ? " (coarsest)"
             : bit + 1u == bits ? " (finest)"
                                : "",
             rides_on, inverse ? ", inverse" : "");
}

static int write_listing(const struct hal_storage *st, const char *dir,
                         const struct gray_layout *full, uint32_t scan_count, uint32_t w,
                         uint32_t h)
{
    char text[16384];
    size_t used = 0;
    uint32_t count = gray_layout_count(full);
    used += (size_t)snprintf(text + used, sizeof(text) - used,
                             "# The projector's stored sequence, %ux%u, 8-bit grey (0 black, 255 "
                             "white).\n# A scan steps through patterns 0..%u, then resets; "
                             "calibration steps through all %u.\n# index file what\n",
                             w, h, scan_count - 1u, count);
    for (uint32_t i = 0; i < count && used < sizeof(text); i++) {
        char what[96];
        describe(full, i, what, sizeof(what));
        used += (size_t)snprintf(text + used, sizeof(text) - used, "%2u pattern_%02u.png %s\n", i,
                                 i, what);
    }
    if (used >= sizeof(text))
        return -ENOSPC;
    char path[HAL_MAX_PATH + 32];
    snprintf(path, sizeof(path), "%s/patterns.txt", dir);
    return hal_storage_write_file(st, path, text, used);
}

int patterns_write(const struct hal_storage *st, const struct app_config *cfg,
                   const struct scan_calib *calib, const char *dir)
{
    const uint32_t w = calib->proj_width, h = calib->proj_height;
    struct scan_params calibration = cfg->scan; /* the calibration's: columns, then rows */
    calibration.decode_rows = 1;
    struct gray_layout full, scan;
    scan_layout(&calibration, calib, &full);
    scan_layout(&cfg->scan, calib, &scan);
    int rc = hal_storage_mkdir_p(st, dir);
    if (rc != 0) {
        fprintf(stderr, "scanner: error: cannot create %s: %s\n", dir, strerror(-rc));
        return rc;
    }
    uint8_t *image = malloc((size_t)w * h); /* a setup command: not the firmware's memory */
    if (image == NULL) {
        fprintf(stderr, "scanner: error: out of memory for a %ux%u pattern\n", w, h);
        return -ENOMEM;
    }
    char path[HAL_MAX_PATH + 32];
    for (uint32_t i = 0; i < gray_layout_count(&full) && rc == 0; i++) {
        for (uint32_t y = 0; y < h; y++)
            for (uint32_t x = 0; x < w; x++)
                image[(size_t)y * w + x] = gray_layout_lit(&full, i, x, y) ? 255u : 0u;
        snprintf(path, sizeof(path), "%s/pattern_%02u.png", dir, i);
        rc = image_write_png(st, path, image, w, h, 1);
    }
    if (rc == 0) {
        snprintf(path, sizeof(path), "%s/patterns.txt", dir);
        rc = write_listing(st, dir, &full, gray_layout_count(&scan), w, h);
    }
    if (rc != 0)
        fprintf(stderr, "scanner: error: cannot write %s: %s\n", path, strerror(-rc));
    else
        printf("%u patterns of %ux%u in %s (patterns.txt says what each is)\n",
               gray_layout_count(&full), w, h, dir);
    free(image);
    return rc;
}
