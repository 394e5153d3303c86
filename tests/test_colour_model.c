/* Intrinsic colour on frames made from its own model (Jost et al. eq. 6 with an offset and an
 * ambient term), without the simulator: a flat row of painted pixels under four lights, so each
 * rule of colour_compute can be checked against the albedo it must give. Dark paint gets no
 * estimate from one exposure and a right one from a bracketed pair with Ca fitted to the
 * albedo; a pixel without any estimate carries no colour; a cast shadow is left out. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "colour.h"
#include "vec3.h"

#define WIDTH 400      /* the four paints below, repeated: Ca's fit needs a hundred pixels */
#define BLACK_DN 51.0  /* the camera's black offset */
#define AMBIENT_DN 3.0 /* indirect light on a white surface at the camera's exposure */
#define LIGHT_DN 100.0 /* each light on a white surface facing it, at the camera's exposure */
#define EXPOSURE_US 10000u

/* The row: bright paint, dark paint, near-white paint (its long frames saturate), and a pixel
 * that light 0 does not reach directly (cast shadow: a fifth of its light, from elsewhere). */
static const double paint[4] = {0.6, 0.05, 0.95, 0.6};
enum { BRIGHT, DARK, WHITE, SHADOWED };
#define albedo(i) paint[(i) % 4]

static struct scene {
    struct scan_calib calib;
    struct colour_params prm;
    struct colour_layout lay;
    uint8_t reason[WIDTH];
    float xyz[3 * WIDTH], normal[3 * WIDTH];
    uint8_t frames[COLOUR_MAX_FRAMES][3 * WIDTH], white[3 * WIDTH];
    const uint8_t *frame_ptr[COLOUR_MAX_FRAMES];
    uint8_t out[3 * WIDTH];
    float confidence[WIDTH];
} s;

/* cos(theta) of light l at pixel i (the row faces the camera, normal -z) */
static double light_cos(uint32_t l, int i)
{
    vec3 p = v3(s.xyz[3 * i], s.xyz[3 * i + 1], s.xyz[3 * i + 2]);
    vec3 to = v3_norm(v3_sub(v3_from(s.calib.light_pos_mm[l]), p));
    return fmax(0.0, v3_dot(to, v3(s.normal[3 * i], s.normal[3 * i + 1], s.normal[3 * i + 2])));
}

/* Every colour frame of the layout, as the camera would give it (no noise, whole grey levels). */
static void render(void)
{
    colour_layout(&s.prm, s.calib.light_count, &s.lay);
    for (uint32_t k = 0; k < s.lay.count; k++) {
        double gain = (double)s.lay.exposure_us[k] / EXPOSURE_US;
        for (int i = 0; i < WIDTH; i++) {
            double sig = AMBIENT_DN * albedo(i);
            for (uint32_t l = 0; l < s.calib.light_count; l++)
                if (s.lay.lights_mask[k] >> l & 1u)
                    sig += LIGHT_DN * albedo(i) * light_cos(l, i) *
                           (i % 4 == SHADOWED && l == 0 ? 0.2 : 1.0);
            double dn = floor(BLACK_DN + sig * gain + 0.5);
            for (int c = 0; c < 3; c++)
                s.frames[k][3 * i + c] = (uint8_t)(dn > 255.0 ? 255.0 : dn);
        }
        s.frame_ptr[k] = s.frames[k];
    }
}

static int setup(void **state)
{
    (void)state;
    memset(&s, 0, sizeof(s));
    for (int i = 0; i < WIDTH; i++) {
        s.reason[i] = SCAN_VALID;
        s.xyz[3 * i] = (float)(i * 0.25 - 50.0); /* 0.25 mm apart, 500 mm from the camera */
        s.xyz[3 * i + 2] = 500.0f;
        s.normal[3 * i + 2] = -1.0f;
    }
    static const double lights[4][3] = {
        {-300, 0, 150}, {300, 0, 150}, {0, -300, 150}, {0, 300, 150}};
    s.calib.light_count = 4;
    for (uint32_t l = 0; l < 4; l++) {
        memcpy(s.calib.light_pos_mm[l], lights[l], sizeof(lights[l]));
        s.calib.light_gain[l] = 1.0;
    }
    s.calib.proj_rot[0] = s.calib.proj_rot[4] = s.calib.proj_rot[8] = 1.0;
    struct colour_params *p = &s.prm;
    p->method = COLOUR_MULTI;
    p->ca = COLOUR_CA_ALBEDO;
    p->min_cos = 0.2;
    p->ke = 40.0;
    p->ko = 2.0;
    p->shadow_dn = 6.0;
    p->shadow_ratio = 0.25;
    p->falloff = 0;
    p->reference_mm = 600.0;
    p->white_scale[0] = p->white_scale[1] = p->white_scale[2] = 1.0 / LIGHT_DN;
    p->saturation_dn = 250;
    p->exposure_us = EXPOSURE_US;
    p->gain_milli = 1000;
    return 0;
}

static void compute(void)
{
    render();
    struct decode_maps m = {NULL, NULL, s.reason, WIDTH, 1};
    struct tri_range r = {s.xyz, s.normal, WIDTH, 1, WIDTH};
    assert_int_equal(colour_compute(&s.prm, NULL, &s.calib, &m, &r, s.white, s.frame_ptr, s.out,
                                    s.confidence, NULL),
                     0);
}

/* The albedo colour_compute gave paint @p i's pixel in the middle of the row (grey paint: the
 * mean of the channels). */
static double got(int i)
{
    i += WIDTH / 2;
    return (s.out[3 * i] + s.out[3 * i + 1] + s.out[3 * i + 2]) / 3.0 / 255.0;
}

/* One exposure: dark paint's signal (under 3 grey levels a light) is within the noise under
 * every light, so it has no estimate; it gets no colour rather than the raw white frame's. */
static void test_no_estimate_carries_no_colour(void **state)
{
    (void)state;
    memset(s.white, 200, sizeof(s.white)); /* a raw colour that must not come through */
    s.prm.bracket = 0;
    compute();
    for (int i = DARK; i < WIDTH; i += 4) {
        assert_true(s.confidence[i] == COLOUR_NO_ESTIMATE);
        assert_int_equal(s.out[3 * i] | s.out[3 * i + 1] | s.out[3 * i + 2], 0);
    }
    assert_true(s.confidence[WIDTH / 2 + BRIGHT] > 0.5f);
    assert_true(fabs(got(BRIGHT) - paint[BRIGHT]) < 0.01);
}

/* Bracketed 4x: the dark paint reads 4x its signal in the longer frames and gets a confident
 * estimate; the near-white paint, saturated there, is read in the shorter ones. */
static void test_bracket_reads_dark_paint(void **state)
{
    (void)state;
    s.prm.bracket = 4;
    compute();
    assert_int_equal(s.lay.count, 2u + 4u + 4u + 1u); /* dark, all, 4 short, 4 long, long dark */
    assert_int_equal(s.lay.exposure_us[s.lay.long_of[COLOUR_FRAME_LIGHT0]], 4 * EXPOSURE_US);
    assert_true(s.frames[s.lay.long_of[COLOUR_FRAME_LIGHT0]][3 * WHITE] >= 250); /* saturated */
    assert_true(s.confidence[WIDTH / 2 + DARK] > 0.5f);
    assert_true(fabs(got(DARK) - paint[DARK]) < 0.1 * paint[DARK]);
    assert_true(fabs(got(WHITE) - paint[WHITE]) < 0.01);
    assert_true(fabs(got(BRIGHT) - paint[BRIGHT]) < 0.01);
}

/* Ca as one mean per channel takes the ambient light of the average paint off the dark paint,
 * far more than the little it reflects: its albedo comes out much too low. Ca fitted to the
 * albedo takes off what the paint itself reflects. */
static void test_ca_follows_the_albedo(void **state)
{
    (void)state;
    s.prm.bracket = 4;
    s.prm.ca = COLOUR_CA_CHANNEL;
    compute();
    double channel = got(DARK);
    s.prm.ca = COLOUR_CA_ALBEDO;
    compute();
    assert_true(channel < 0.8 * paint[DARK]);
    assert_true(fabs(got(DARK) - paint[DARK]) < 0.5 * fabs(channel - paint[DARK]));
}

/* A light that reaches the pixel only by way of other surfaces says a tenth of the albedo the
 * others say: with shadow_ratio it is left out, without it the estimate falls with it. */
static void test_cast_shadow_left_out(void **state)
{
    (void)state;
    s.prm.bracket = 0;
    s.prm.shadow_ratio = 0.25;
    compute();
    double with = got(SHADOWED);
    s.prm.shadow_ratio = 0.0;
    compute();
    double without = got(SHADOWED);
    assert_true(fabs(with - paint[SHADOWED]) < 0.015);
    assert_true(without < paint[SHADOWED] - 0.05);
}

/* Which colour frames each method reads (a scan takes them all; scanner process reads back only
 * these): with a bracket and the all-lights and single-light frames at their own exposures, so
 * that each of them has a dark frame of its own. A frame a method reads, missing, is refused; one
 * it does not read may be missing and changes nothing. */
static void test_each_method_reads_its_frames(void **state)
{
    (void)state;
    s.prm.bracket = 4;
    s.prm.all_lights_exposure_us = EXPOSURE_US / 2;
    s.prm.light_exposure_us = EXPOSURE_US * 2;
    colour_layout(&s.prm, s.calib.light_count, &s.lay);
    const struct colour_layout *l = &s.lay;
    /* dark, all, 4 lights, 4 bracketed, then the darks at 5, 20 and 80 ms */
    assert_int_equal(l->count, 13);
    const uint32_t all_dark = l->dark_of[COLOUR_FRAME_ALL];
    const uint32_t light_dark = l->dark_of[COLOUR_FRAME_LIGHT0];
    const uint32_t long_dark = l->dark_of[l->long_of[COLOUR_FRAME_LIGHT0]];
    assert_true(all_dark != COLOUR_FRAME_DARK && light_dark != all_dark && long_dark != light_dark);
    for (uint32_t k = 0; k < l->count; k++) {
        int light = k >= COLOUR_FRAME_LIGHT0 && l->lights_mask[k] != 0;
        struct colour_params p = s.prm;
        p.method = COLOUR_NONE;
        assert_int_equal(colour_needs_frame(&p, l, k), 0);
        p.method = COLOUR_SINGLE;
        assert_int_equal(colour_needs_frame(&p, l, k), k == COLOUR_FRAME_DARK);
        p.method = COLOUR_UNIFORM;
        assert_int_equal(colour_needs_frame(&p, l, k), k == COLOUR_FRAME_ALL || k == all_dark);
        for (p.method = COLOUR_MULTI; p.method <= COLOUR_FIT; p.method++)
            assert_int_equal(colour_needs_frame(&p, l, k),
                             light || k == light_dark || k == long_dark);
    }
    assert_int_equal(colour_needs_frame(&s.prm, l, l->count), 0);

    compute(); /* multi, every frame there */
    uint8_t every[3 * WIDTH];
    memcpy(every, s.out, sizeof(every));
    struct decode_maps m = {NULL, NULL, s.reason, WIDTH, 1};
    struct tri_range r = {s.xyz, s.normal, WIDTH, 1, WIDTH};
    s.frame_ptr[COLOUR_FRAME_ALL] = s.frame_ptr[all_dark] = s.frame_ptr[COLOUR_FRAME_DARK] = NULL;
    assert_int_equal(colour_compute(&s.prm, NULL, &s.calib, &m, &r, s.white, s.frame_ptr, s.out,
                                    s.confidence, NULL),
                     0);
    assert_memory_equal(s.out, every, sizeof(every));
    s.frame_ptr[long_dark] = NULL;
    assert_int_equal(colour_compute(&s.prm, NULL, &s.calib, &m, &r, s.white, s.frame_ptr, s.out,
                                    s.confidence, NULL),
                     -EINVAL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_no_estimate_carries_no_colour, setup),
        cmocka_unit_test_setup(test_bracket_reads_dark_paint, setup),
        cmocka_unit_test_setup(test_ca_follows_the_albedo, setup),
        cmocka_unit_test_setup(test_cast_shadow_left_out, setup),
        cmocka_unit_test_setup(test_each_method_reads_its_frames, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
