/* Decoder on synthetic frames: right columns, and a reason code for every kind of bad pixel. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <string.h>

#include "decode.h"
#include "gray.h"

#define W 64
#define H 8
#define PROJ_W 64

static struct decode_ctx dec;   /* the decoder under test */
static struct decode_work work; /* and its working planes */
static uint8_t frame[W * H * 3];
static uint8_t fed[DECODE_MAX_PATTERNS][W * H]; /* every grey frame fed, for the reference */

/* The decoder sees grey frames, converted as the scan converts camera frames. */
static int feed(uint32_t pattern)
{
    uint8_t *grey = fed[pattern < DECODE_MAX_PATTERNS ? pattern : 0];
    decode_rgb_to_grey(frame, grey, W * H, 250);
    return decode_frame(&dec, pattern, grey);
}

static struct scan_params params(void)
{
    struct scan_params p;
    memset(&p, 0, sizeof(p));
    p.width = W;
    p.height = H;
    p.min_contrast_dn = 10;
    p.shadow_contrast_dn = 5;
    p.min_bit_diff_dn = 4;
    p.max_ambiguous_bits = 1;
    p.max_unclear_bits = 4;
    p.saturation_dn = 250;
    p.max_column_jump = 3;
    p.min_consistent_neighbours = 3;
    return p;
}

/* Pixel (x, y) sees projector column x; rows choose the surface: 0-3 normal, 4 shadow (no
 * projector light), 5 dark paint, 6 saturated wherever the projector lights it, 7 normal but
 * for pixel 30, saturated in every frame. */
static uint32_t render_code = GRAY_CODE_GRAY; /* how the projector codes its columns */
static uint32_t render_inverse = 0;           /* its finest bits with an inverse (0: all) */

static struct gray_layout layout_of(uint32_t bits)
{
    struct gray_layout l = {bits, 0, render_code, render_inverse};
    return l;
}

static uint32_t pattern_count(uint32_t bits)
{
    struct gray_layout l = layout_of(bits);
    return gray_layout_count(&l);
}

static void render(uint32_t pattern, uint32_t bits)
{
    struct gray_layout l = layout_of(bits);
    for (uint32_t y = 0; y < H; y++) {
        for (uint32_t x = 0; x < W; x++) {
            int lit = gray_layout_lit(&l, pattern, x, 0);
            double gain = y == 4 ? 0.0 : y == 5 ? 0.03 : 1.0;
            double v = 51.0 + gain * (lit ? 150.0 : 2.0);
            if ((y == 6 && lit) || (y == 7 && x == 30))
                v = 255.0;
            uint8_t *px = &frame[3 * (y * W + x)];
            px[0] = px[1] = px[2] = (uint8_t)v;
        }
    }
}

/* What the decoder hands back: the reason map (ours) and its column map. */
static uint8_t reason_out[W * H];
static struct decode_maps maps_out;

static int begin(struct scan_params *p, uint32_t bits)
{
    struct gray_layout l = layout_of(bits);
    return decode_begin(&dec, &work, p, &l, PROJ_W, 1);
}

static void decode_all(uint32_t bits)
{
    struct scan_params p = params();
    assert_int_equal(begin(&p, bits), 0);
    for (uint32_t i = 0; i < pattern_count(bits); i++) {
        render(i, bits);
        assert_int_equal(feed(i), 0);
    }
    assert_int_equal(decode_finish(&dec, NULL, reason_out, &maps_out), 0);
}

static void test_columns_and_reasons(void **state)
{
    (void)state;
    uint32_t bits = gray_bits_for_width(PROJ_W);
    decode_all(bits);
    const struct decode_maps *m = &maps_out;
    for (uint32_t x = 0; x < W; x++) {
        for (uint32_t y = 0; y < 4; y++) {
            assert_int_equal(m->reason[y * W + x], SCAN_VALID);
            assert_int_equal(m->column[y * W + x], x);
        }
        assert_int_equal(m->reason[4 * W + x], SCAN_SHADOW);
        assert_int_equal(m->reason[5 * W + x], SCAN_SHADOW); /* 0.03 * 148 = 4 <= 5 */
        /* each pattern's pair has one frame unsaturated: which is brighter is still clear */
        assert_int_equal(m->reason[6 * W + x], SCAN_VALID);
        assert_int_equal(m->column[6 * W + x], x);
    }
    assert_int_equal(m->reason[7 * W + 30], SCAN_SATURATED); /* even black: no contrast known */
    assert_int_equal(m->reason[7 * W + 31], SCAN_VALID);
    assert_string_equal(scan_reason_name(SCAN_LOW_CONTRAST), "low_contrast");
}

/* Saturation in any channel marks the grey pixel; real grey levels never reach the mark. */
static void test_grey_conversion(void **state)
{
    (void)state;
    const uint8_t rgb[4 * 3] = {255, 255, 255, 10, 250, 10, 249, 249, 249, 0, 0, 0};
    uint8_t g[4];
    decode_rgb_to_grey(rgb, g, 4, 250);
    assert_int_equal(g[0], DECODE_SATURATED);
    assert_int_equal(g[1], DECODE_SATURATED); /* one channel is enough */
    assert_int_equal(g[2], 249);              /* weights sum to 256: a grey stays itself */
    assert_int_equal(g[3], 0);
    decode_rgb_to_grey(rgb, g, 1, 256); /* no saturation level: 255 still cannot be a grey */
    assert_int_equal(g[0], 254);
}

static void test_frames_out_of_order_rejected(void **state)
{
    (void)state;
    struct scan_params p = params();
    assert_int_equal(begin(&p, 6), 0);
    render(0, 6);
    assert_int_equal(feed(1), -EINVAL);
    assert_int_equal(feed(0), 0);
    assert_int_equal(decode_finish(&dec, NULL, reason_out, &maps_out),
                     -EINVAL); /* frames missing */
}

static void test_size_above_limit_rejected(void **state)
{
    (void)state;
    struct scan_params p = params();
    p.width = HAL_MAX_WIDTH + 2;
    assert_int_equal(begin(&p, 6), -EINVAL);
    p = params();
    assert_int_equal(begin(&p, 17), -EINVAL);
    struct gray_layout too_many = {16, 16, GRAY_CODE_GRAY, 0}; /* more than the store holds */
    assert_int_equal(decode_begin(&dec, &work, &p, &too_many, PROJ_W, 1), -EINVAL);
    struct gray_layout fits = {6, 0, GRAY_CODE_GRAY, 0};
    assert_int_equal(decode_begin(&dec, NULL, &p, &fits, PROJ_W, 1), -EINVAL); /* no planes */
    assert_int_equal(decode_begin(&dec, &work, &p, &fits, PROJ_W, 1), 0);
}

/* Every pattern of the synthetic scene, with pixel 10 of row 0 ambiguous in bit 0 and pixel 20
 * ambiguous in bits 0 and 1: the mean of white and black (201, 53) in those bits' frames. */
static void feed_ambiguous_scene(uint32_t bits)
{
    struct gray_layout l = layout_of(bits);
    for (uint32_t i = 0; i < pattern_count(bits); i++) {
        render(i, bits);
        int is_row, inverse;
        uint32_t k = 99;
        gray_layout_pattern(&l, i, &is_row, &k, &inverse);
        if (k == 0)
            memset(&frame[3 * 10], 127, 3);
        if (k <= 1)
            memset(&frame[3 * 20], 127, 3);
        assert_int_equal(feed(i), 0);
    }
}

/* One unclear bit is a column edge: either reading is one of two neighbouring columns. Two are
 * resolved by the neighbourhood (the reading its decoded neighbours predict), unless more than
 * max_unclear_bits are allowed to be. */
static void test_ambiguous_bits(void **state)
{
    (void)state;
    uint32_t bits = gray_bits_for_width(PROJ_W);
    struct scan_params p = params();
    assert_int_equal(begin(&p, bits), 0);
    feed_ambiguous_scene(bits);
    assert_int_equal(decode_finish(&dec, NULL, reason_out, &maps_out), 0);
    const struct decode_maps *m = &maps_out;
    assert_int_equal(m->reason[10], SCAN_VALID);
    assert_int_equal(m->reason[20], SCAN_VALID);
    assert_int_equal(m->column[20], 20);
    p.max_unclear_bits = 1;
    assert_int_equal(begin(&p, bits), 0);
    feed_ambiguous_scene(bits);
    assert_int_equal(decode_finish(&dec, NULL, reason_out, &maps_out), 0);
    assert_int_equal(m->reason[10], SCAN_VALID);
    assert_int_equal(m->reason[20], SCAN_LOW_CONTRAST);
}

/* The bit threshold follows the camera's noise at the pixel's contrast, never below the floor:
 * sigma^2 = 2 read^2 + contrast / gain. */
static void test_bit_threshold_from_noise(void **state)
{
    (void)state;
    struct scan_params p = params();
    assert_int_equal(decode_bit_threshold(&p, 100), 4); /* no noise model: the fixed floor */
    p.read_noise_dn = 1.5;
    p.electrons_per_dn = 20.0;
    p.bit_noise_sigmas = 2.0;
    assert_int_equal(decode_bit_threshold(&p, 100), 7); /* 2 sqrt(4.5 + 5) = 6.2 */
    assert_int_equal(decode_bit_threshold(&p, 200), 8); /* 2 sqrt(4.5 + 10) = 7.6 */
    assert_int_equal(decode_bit_threshold(&p, 0), 5);   /* 2 sqrt(4.5) = 4.2 */
    p.min_bit_diff_dn = 12;
    assert_int_equal(decode_bit_threshold(&p, 100), 12);
}

/* A pixel whose code is wrong in a high bit disagrees with its neighbours. */
static void test_lone_wrong_code_inconsistent(void **state)
{
    (void)state;
    uint32_t bits = gray_bits_for_width(PROJ_W);
    struct scan_params p = params();
    assert_int_equal(begin(&p, bits), 0);
    for (uint32_t i = 0; i < gray_pattern_count(bits); i++) {
        render(i, bits);
        if (i == 2 || i == 3) { /* flip the top bit of pixel (10, 2): column 10 reads as 53 */
            int lit = gray_pattern_lit(bits, i == 2 ? 3 : 2, 10);
            memset(&frame[3 * (2 * W + 10)], lit ? 201 : 53, 3);
        }
        assert_int_equal(feed(i), 0);
    }
    assert_int_equal(decode_finish(&dec, NULL, reason_out, &maps_out), 0);
    const struct decode_maps *m = &maps_out;
    assert_int_equal(m->reason[2 * W + 10], SCAN_INCONSISTENT);
    assert_int_equal(m->reason[2 * W + 11], SCAN_VALID);
}

/* The blocked decoder and the plain reference agree on frames with every kind of pixel: run the
 * ambiguous-bit scene through both, with settings @p p. @retval the kinds of reason seen */
static unsigned blocked_matches_reference_with(const struct scan_params *p)
{
    uint32_t bits = gray_bits_for_width(PROJ_W);
    struct gray_layout l = layout_of(bits);
    assert_int_equal(decode_begin(&dec, &work, p, &l, PROJ_W, 1), 0);
    feed_ambiguous_scene(bits);
    assert_int_equal(decode_pixels(&dec, NULL, reason_out, &maps_out), 0);
    const uint8_t *frames[DECODE_MAX_PATTERNS];
    for (uint32_t i = 0; i < pattern_count(bits); i++)
        frames[i] = fed[i];
    uint16_t col[W * H];
    uint8_t reason[W * H];
    decode_reference(p, &l, PROJ_W, 1, frames, W * H, col, NULL, reason);
    const struct decode_maps *m = &maps_out;
    unsigned kinds = 0;
    for (size_t i = 0; i < W * H; i++) {
        assert_int_equal(m->reason[i], reason[i]);
        kinds |= 1u << reason[i];
        if (reason[i] == SCAN_VALID)
            assert_int_equal(m->column[i], col[i]);
    }
    return kinds;
}

static void test_blocked_matches_reference(void **state)
{
    (void)state;
    struct scan_params p = params();
    /* valid, shadow, low contrast and saturated pixels were all compared */
    assert_true((blocked_matches_reference_with(&p) & 0x1Bu) == 0x1Bu);
}

/* The same at each end of every setting the per-pixel stage compares with (the ranges
 * app/config.c allows), its planes left full of ones by an earlier view first: a view's bits
 * are written whole by its own frames, none read from the view before. */
static void test_blocked_matches_reference_at_every_limit(void **state)
{
    (void)state;
    static const uint32_t shadow[] = {0, 4, 254}, dark[] = {1, 255, 255};
    static const uint32_t ambiguous[] = {0, 1, 16};
    unsigned kinds = 0;
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++) {
            struct scan_params p = params();
            p.shadow_contrast_dn = shadow[k];
            p.min_contrast_dn = dark[k];
            p.max_ambiguous_bits = ambiguous[a];
            for (int axis = 0; axis < 2; axis++) {
                memset(work.word_hi[axis], 0xFF, W * H);
                memset(work.word_lo[axis], 0xFF, W * H);
                memset(work.unclear_hi[axis], 0xFF, W * H);
                memset(work.unclear_lo[axis], 0xFF, W * H);
            }
            memset(work.sat, 0xFF, W * H);
            kinds |= blocked_matches_reference_with(&p);
        }
    /* every reason but inconsistent (the neighbour check's) came up */
    assert_int_equal(kinds, (1u << SCAN_INCONSISTENT) - 1u);
}

/* XOR-04 decodes the same scene to the same columns and reasons, blocked and plain alike. */
static void test_xor04_columns_and_reference(void **state)
{
    render_code = GRAY_CODE_XOR04;
    test_columns_and_reasons(state);
    test_ambiguous_bits(state);
    test_blocked_matches_reference(state);
    render_code = GRAY_CODE_GRAY;
}

/* Inverses for the finest 3 bits only ([scan] inverse_bits): the coarser bits read against the
 * mean of white and black, three frames fewer, the same columns and reasons, blocked and plain
 * alike; Gray and XOR-04. */
static void test_fewer_inverses(void **state)
{
    uint32_t bits = gray_bits_for_width(PROJ_W);
    render_inverse = 3;
    assert_int_equal(pattern_count(bits), 2 + bits + 3);
    for (render_code = GRAY_CODE_GRAY; render_code <= GRAY_CODE_XOR04; render_code++) {
        test_columns_and_reasons(state);
        test_ambiguous_bits(state);
        test_blocked_matches_reference(state);
    }
    render_code = GRAY_CODE_GRAY;
    render_inverse = 0;
}

/* Frames as a reader of kept frames hands them over (scanner process): frame i + 1 read into its
 * slot before frame i is handed over wherever @p ahead says so. @retval frames read ahead */
static unsigned decode_reading_ahead(uint32_t bits, int (*ahead)(uint32_t i))
{
    struct scan_params p = params();
    unsigned read_ahead = 0;
    assert_int_equal(begin(&p, bits), 0);
    for (uint32_t i = 0, count = pattern_count(bits); i < count;) {
        uint32_t n = i + 1 < count && ahead(i) ? 2u : 1u;
        for (uint32_t k = i; k < i + n; k++) {
            render(k, bits);
            decode_rgb_to_grey(frame, decode_frame_slot(&dec, k), W * H, 250);
        }
        for (uint32_t k = i; k < i + n; k++)
            assert_int_equal(decode_frame(&dec, k, decode_frame_slot(&dec, k)), 0);
        read_ahead += n - 1u;
        i += n;
    }
    assert_int_equal(decode_finish(&dec, NULL, reason_out, &maps_out), 0);
    return read_ahead;
}

static int ahead_where_free(uint32_t i)
{
    return decode_slot_free_before(&dec, i, i + 1);
}

/* scanner process until 2026-12-07: two frames at a time wherever their slots differ */
static int ahead_where_slots_differ(uint32_t i)
{
    return decode_frame_slot(&dec, i) != decode_frame_slot(&dec, i + 1);
}

/* A frame read into its slot before the one before it is handed over, where the decoder says
 * the slot is free, decodes as frames handed over one by one; with every inverse and with the
 * finest 3 only, Gray and XOR-04. Where the coarse bits have none, reading ahead wherever the
 * slots differ reads an inverse against the next bit's stripes (what scanner process did). */
static void test_read_ahead_where_free(void **state)
{
    (void)state;
    static uint8_t reason1[W * H];
    static uint16_t column1[W * H];
    uint32_t bits = gray_bits_for_width(PROJ_W);
    for (render_inverse = 0; render_inverse <= 3; render_inverse += 3)
        for (render_code = GRAY_CODE_GRAY; render_code <= GRAY_CODE_XOR04; render_code++) {
            decode_all(bits);
            memcpy(reason1, reason_out, sizeof(reason1));
            memcpy(column1, maps_out.column, sizeof(column1));
            /* white and black, and each bit's stripes and inverse */
            unsigned pairs = 1u + (render_inverse ? render_inverse : bits);
            assert_int_equal(decode_reading_ahead(bits, ahead_where_free), pairs);
            assert_memory_equal(reason_out, reason1, sizeof(reason1));
            assert_memory_equal(maps_out.column, column1, sizeof(column1));
            decode_reading_ahead(bits, ahead_where_slots_differ);
            int same = memcmp(reason_out, reason1, sizeof(reason1)) == 0 &&
                       memcmp(maps_out.column, column1, sizeof(column1)) == 0;
            assert_int_equal(same, render_inverse == 0);
        }
    render_code = GRAY_CODE_GRAY;
    render_inverse = 0;
}

/* A bit read against the mean: a quarter of the pair's threshold, rounded up. */
static void test_mean_threshold(void **state)
{
    (void)state;
    struct scan_params p = params();
    assert_int_equal(decode_mean_threshold(&p, 100), 1); /* the pair's floor 4 */
    p.read_noise_dn = 1.5;
    p.electrons_per_dn = 20.0;
    p.bit_noise_sigmas = 2.0;
    assert_int_equal(decode_mean_threshold(&p, 100), 2); /* the pair's 7 */
    p.min_bit_diff_dn = 12;
    assert_int_equal(decode_mean_threshold(&p, 100), 3); /* the pair's 12 */
}

/* Without rows coded the rows' planes are neither read nor written (decode.c maps and clears
 * none of them): planes left full of ones by an earlier view that coded rows change nothing, in
 * the per-pixel stage or the neighbourhood's (its unclear pixels resolved), and stay as they
 * were. */
static void test_row_planes_untouched_without_rows(void **state)
{
    (void)state;
    static uint8_t reason1[W * H];
    static uint16_t column1[W * H];
    uint32_t bits = gray_bits_for_width(PROJ_W);
    struct scan_params p = params();
    struct gray_layout l = layout_of(bits);
    assert_int_equal(l.row_bits, 0);
    assert_int_equal(decode_begin(&dec, &work, &p, &l, PROJ_W, 1), 0);
    feed_ambiguous_scene(bits);
    assert_int_equal(decode_finish(&dec, NULL, reason1, &maps_out), 0);
    assert_null(maps_out.row);
    memcpy(column1, maps_out.column, sizeof(column1));
    assert_int_equal(reason1[20], SCAN_VALID); /* resolved by its neighbourhood */
    memset(work.word_hi[1], 0xFF, W * H);
    memset(work.word_lo[1], 0xFF, W * H);
    memset(work.unclear_hi[1], 0xFF, W * H);
    memset(work.unclear_lo[1], 0xFF, W * H);
    memset(dec.row_map, 0xFF, W * H * sizeof(uint16_t));
    memset(work.unclear_row, 0xFF, W * H * sizeof(uint16_t));
    assert_int_equal(decode_begin(&dec, &work, &p, &l, PROJ_W, 1), 0);
    feed_ambiguous_scene(bits);
    assert_int_equal(decode_finish(&dec, NULL, reason_out, &maps_out), 0);
    assert_memory_equal(reason_out, reason1, sizeof(reason1));
    for (size_t i = 0; i < W * H; i++) {
        if (reason1[i] == SCAN_VALID)
            assert_int_equal(maps_out.column[i], column1[i]);
        assert_int_equal(dec.row_map[i], 0xFFFFu);
        assert_int_equal(work.unclear_row[i], 0xFFFFu);
        assert_int_equal(work.word_hi[1][i] & work.unclear_lo[1][i], 0xFF);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_columns_and_reasons),
        cmocka_unit_test(test_grey_conversion),
        cmocka_unit_test(test_frames_out_of_order_rejected),
        cmocka_unit_test(test_size_above_limit_rejected),
        cmocka_unit_test(test_ambiguous_bits),
        cmocka_unit_test(test_bit_threshold_from_noise),
        cmocka_unit_test(test_lone_wrong_code_inconsistent),
        cmocka_unit_test(test_blocked_matches_reference),
        cmocka_unit_test(test_blocked_matches_reference_at_every_limit),
        cmocka_unit_test(test_xor04_columns_and_reference),
        cmocka_unit_test(test_fewer_inverses),
        cmocka_unit_test(test_read_ahead_where_free),
        cmocka_unit_test(test_mean_threshold),
        cmocka_unit_test(test_row_planes_untouched_without_rows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
