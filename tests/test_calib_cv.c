/* The calibration's weighted joint solve (calib/calib_cv.cpp calcv_refine_weighted) on board
 * corners made up for a known camera, projector and pose, with half of the views' corners found
 * five times less exactly: its results nearer the truth than the solve that weighs every corner
 * alike, and the uncertainty it states as large as its spread over noise draws. */
#define _DEFAULT_SOURCE /* M_PI */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <string.h>

#include "calib_cv.h"

#define VIEWS 12
#define DRAWS 24
#define COLS 9
#define ROWS 7
#define PITCH_MM 25.0

static const struct calcv_lens true_cam = {2400.0, 2396.0, 640.0, 480.0, {0}};
static const struct calcv_lens true_proj = {1870.0, 1875.0, 506.0, 390.0, {0}};
static const double true_trans_mm[3] = {-250.0, -16.0, 58.0};
static double true_rot[9]; /* the camera -> projector rotation: 25 degrees about y */

/* A fixed sequence of standard normal numbers (xorshift, Box-Muller): the same test each run. */
static uint64_t rng_state = 88172645463325252ULL;
static double uniform(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return ((double)(rng_state >> 11) + 0.5) / 9007199254740992.0;
}
static double gaussian(void)
{
    return sqrt(-2.0 * log(uniform())) * cos(2.0 * M_PI * uniform());
}

/* Pinhole projection of camera-frame point @p p through @p l. */
static void project(const struct calcv_lens *l, const double p[3], double px[2])
{
    px[0] = l->fx * p[0] / p[2] + l->cx;
    px[1] = l->fy * p[1] / p[2] + l->cy;
}

static void transform(const double r[9], const double t[3], const double p[3], double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = r[3 * i] * p[0] + r[3 * i + 1] * p[1] + r[3 * i + 2] * p[2] + t[i];
}

/* View @p v's board, tilted up to 35 degrees each way, 550-700 mm away, its corners in the
 * camera and the projector with noise of @p noise_px (one standard deviation). */
static void make_view(int v, double noise_px, struct calcv_corners *cam, struct calcv_corners *proj)
{
    const double tilt_x = (v % 4 - 1.5) * 0.4, tilt_y = (v / 4 - 1.0) * 0.55;
    const double rvec[3] = {M_PI + tilt_x, tilt_y, 0.05 * (v % 3)};
    const double tvec[3] = {10.0 * (v % 3) - 10.0, 0.0, 550.0 + 15.0 * v};
    double r[9];
    calcv_rodrigues(rvec, r);
    cam->count = proj->count = 0;
    for (int j = 0; j < ROWS; j++)
        for (int i = 0; i < COLS; i++) {
            const double sheet[3] = {(i - (COLS - 1) / 2.0) * PITCH_MM,
                                     (j - (ROWS - 1) / 2.0) * PITCH_MM, 0.0};
            double pc[3], pp[3];
            transform(r, tvec, sheet, pc);
            transform(true_rot, true_trans_mm, pc, pp);
            int n = cam->count++;
            proj->count++;
            cam->id[n] = proj->id[n] = n;
            memcpy(cam->sheet[n], sheet, sizeof(sheet));
            memcpy(proj->sheet[n], sheet, sizeof(sheet));
            project(&true_cam, pc, cam->image[n]);
            project(&true_proj, pp, proj->image[n]);
            for (int k = 0; k < 2; k++) {
                cam->image[n][k] += noise_px * gaussian();
                proj->image[n][k] += noise_px * gaussian();
            }
        }
}

struct stats {
    double sum, sum_sq, err_sq, sigma;
};

static void add(struct stats *s, double value, double truth, double sigma)
{
    s->sum += value;
    s->sum_sq += value * value;
    s->err_sq += (value - truth) * (value - truth);
    s->sigma += sigma;
}

static double spread(const struct stats *s)
{
    double mean = s->sum / DRAWS;
    return sqrt(fmax(0.0, (s->sum_sq - DRAWS * mean * mean) / (DRAWS - 1)));
}

static void test_weighted_solve_is_nearer_and_states_its_spread(void **state)
{
    (void)state;
    static struct calcv_corners cam[VIEWS], proj[VIEWS];
    const double rot_y[3] = {0.0, 25.0 * M_PI / 180.0, 0.0};
    calcv_rodrigues(rot_y, true_rot);
    /* projector cx, camera cx, translation z: the values issue 31 measured stated too wide */
    struct stats plain[3] = {{0}}, weighted[3] = {{0}};
    for (int d = 0; d < DRAWS; d++) {
        for (int v = 0; v < VIEWS; v++)
            make_view(v, v % 2 ? 0.10 : 0.02, &cam[v], &proj[v]);
        struct calcv_lens cl = true_cam, pl = true_proj;
        double rot[9], trans[3], rms;
        assert_int_equal(calcv_stereo(cam, proj, VIEWS, 1, &cl, &pl, rot, trans, &rms), 0);
        add(&plain[0], pl.cx, true_proj.cx, 0.0);
        add(&plain[1], cl.cx, true_cam.cx, 0.0);
        add(&plain[2], trans[2], true_trans_mm[2], 0.0);
        struct calcv_sigma sigma;
        assert_int_equal(
            calcv_refine_weighted(cam, proj, VIEWS, 1, &cl, &pl, rot, trans, &sigma, NULL, 0), 0);
        add(&weighted[0], pl.cx, true_proj.cx, sigma.proj[2]);
        add(&weighted[1], cl.cx, true_cam.cx, sigma.cam[2]);
        add(&weighted[2], trans[2], true_trans_mm[2], sigma.trans_mm[2]);
    }
    const char *name[3] = {"projector cx", "camera cx", "translation z"};
    for (int i = 0; i < 3; i++) {
        double stated = weighted[i].sigma / DRAWS;
        double err_w = sqrt(weighted[i].err_sq / DRAWS), err_p = sqrt(plain[i].err_sq / DRAWS);
        print_message("%s: error alike %.4f, weighted %.4f; spread %.4f, stated %.4f\n", name[i],
                      err_p, err_w, spread(&weighted[i]), stated);
        /* a third nearer at least: the noisy half weighs 1/25 of the rest */
        assert_true(err_w < 0.67 * err_p);
        /* honest: the stated sigma within 1.6x of the spread either way (24 draws know a
         * spread to about 15%) */
        assert_true(spread(&weighted[i]) > stated / 1.6 && spread(&weighted[i]) < stated * 1.6);
    }
}

/* Corners without noise (a synthetic rig, a test): the solve stays at the truth and states
 * finite, tiny deviations, its variances estimated from residuals of 1e-13 px. */
static void test_exact_corners_stay_exact(void **state)
{
    (void)state;
    static struct calcv_corners cam[VIEWS], proj[VIEWS];
    const double rot_y[3] = {0.0, 25.0 * M_PI / 180.0, 0.0};
    calcv_rodrigues(rot_y, true_rot);
    for (int v = 0; v < VIEWS; v++)
        make_view(v, 0.0, &cam[v], &proj[v]);
    struct calcv_lens cl = true_cam, pl = true_proj;
    double rot[9], trans[3];
    memcpy(rot, true_rot, sizeof(rot));
    memcpy(trans, true_trans_mm, sizeof(trans));
    struct calcv_sigma sigma;
    assert_int_equal(
        calcv_refine_weighted(cam, proj, VIEWS, 1, &cl, &pl, rot, trans, &sigma, NULL, 0), 0);
    assert_true(fabs(pl.cx - true_proj.cx) < 1e-3 && fabs(cl.fx - true_cam.fx) < 1e-3);
    assert_true(fabs(trans[2] - true_trans_mm[2]) < 1e-4);
    for (int i = 0; i < 4; i++)
        assert_true(isfinite(sigma.proj[i]) && sigma.proj[i] < 1e-3);
}

/* Too few corners for the unknowns: refused, and the lenses left as they were. */
static void test_too_few_corners_are_refused(void **state)
{
    (void)state;
    static struct calcv_corners cam[2], proj[2];
    const double rot_y[3] = {0.0, 25.0 * M_PI / 180.0, 0.0};
    calcv_rodrigues(rot_y, true_rot);
    for (int v = 0; v < 2; v++) {
        make_view(v, 0.02, &cam[v], &proj[v]);
        cam[v].count = proj[v].count = 4; /* 32 residuals for 34 unknowns */
    }
    struct calcv_lens cl = true_cam, pl = true_proj;
    double rot[9], trans[3];
    memcpy(rot, true_rot, sizeof(rot));
    memcpy(trans, true_trans_mm, sizeof(trans));
    struct calcv_sigma sigma;
    assert_int_equal(calcv_refine_weighted(cam, proj, 2, 1, &cl, &pl, rot, trans, &sigma, NULL, 0),
                     -EINVAL);
    assert_memory_equal(&cl, &true_cam, sizeof(cl));
    assert_memory_equal(&pl, &true_proj, sizeof(pl));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_weighted_solve_is_nearer_and_states_its_spread),
        cmocka_unit_test(test_exact_corners_stay_exact),
        cmocka_unit_test(test_too_few_corners_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
