/* Prints decoding rate, depth error and time per view for simulated objects (make measure). */
#define _POSIX_C_SOURCE 200809L
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* --inverse-bits N: every view with inverses for the finest N bits only ([scan] inverse_bits);
 * -1: as each config says. */
static long inverse_bits = -1;

/* One view of the rig @p t (loaded, set as the table wants), measured and timed; 0 ok. */
static int measure_rig(struct test_rig *t, struct view_quality *q, double *ms)
{
    if (inverse_bits >= 0)
        t->cfg.scan.inverse_bits = (uint32_t)inverse_bits;
    if (test_rig_start(t) != 0)
        return 1;
    struct scan_view view;
    struct scan_view_info info;
    double t0 = now_ms();
    int rc = scan_take_view(t->scan, &t->hal, &t->cfg.scan, &t->calib, 0, NULL, &view, &info);
    *ms = now_ms() - t0;
    if (rc == 0)
        test_measure_view(sim_ctl_rig(), &view, q);
    test_rig_stop(t);
    return rc != 0;
}

/* One view of @p object in @p material under the rig of @p config, with the HDR exposures
 * @p exposures (NULL: none; a list ending in 0); 0 ok. */
static int measure_hdr(const char *config, const char *object, const char *material, int refine,
                       const uint32_t *exposures, struct view_quality *q, double *ms)
{
    static struct test_rig t;
    if (test_rig_load(&t, config) != 0)
        return 1;
    t.cfg.scan.exposure_count = 0;
    for (; exposures != NULL && exposures[t.cfg.scan.exposure_count] != 0;
         t.cfg.scan.exposure_count++)
        t.cfg.scan.exposures_us[t.cfg.scan.exposure_count] = exposures[t.cfg.scan.exposure_count];
    snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "%s", object);
    snprintf(t.cfg.sim.material, sizeof(t.cfg.sim.material), "%s", material);
    t.cfg.scan.refine = (uint32_t)refine;
    return measure_rig(&t, q, ms);
}

static int measure_one(const char *config, const char *object, const char *material, int refine,
                       struct view_quality *q, double *ms)
{
    return measure_hdr(config, object, material, refine, NULL, q, ms);
}

static const char *shown(const char *object)
{
    return strcmp(object, "mesh") == 0 ? "bunny" : object;
}

/* The first table: every object and material, refinement off and on. */
static int table_objects(const char *config)
{
    const char *objects[] = {"sphere", "mesh", "cylinder", "box", "torus"};
    const char *materials[] = {"lambert", "phong"};
    printf("| object | material | lit px | decoded right (+-1) | same, incidence < 75 deg, not "
           "dark paint | dark paint flagged | valid px | depth RMS mm | RMS / distance | max dist. "
           "to surface mm | "
           "points > 2 mm | normal error deg | refine | view ms |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (size_t o = 0; o < sizeof(objects) / sizeof(objects[0]); o++)
        for (size_t m = 0; m < sizeof(materials) / sizeof(materials[0]); m++)
            for (int refine = 0; refine <= 1; refine++) {
                struct view_quality q;
                double ms;
                if (measure_one(config, objects[o], materials[m], refine, &q, &ms) != 0)
                    return 1;
                printf("| %s | %s | %u | %.2f%% | %.2f%% | %u of %u | %u | %.3f | %.3f%% | %.2f | "
                       "%u | %.1f | %s | %.0f |\n",
                       shown(objects[o]), materials[m], q.lit, 100.0 * q.lit_correct / q.lit,
                       100.0 * q.lit_head_on_correct / q.lit_head_on, q.dark_flagged, q.dark,
                       q.valid, q.depth_rms_mm, 100.0 * q.depth_rms_mm / q.distance_mm,
                       q.max_surface_mm, q.outliers_2mm, q.normal_err_deg, refine ? "on" : "off",
                       ms);
            }
    return 0;
}

/* The second table (issue 16): decoding where the finest stripe is at the camera's limit. The
 * lit surface is the projector-lit surface at incidence below 75 degrees, dark paint aside. */
static int table_limit(const char *config)
{
    const char *objects[] = {"sphere", "mesh", "box", "torus"};
    const char *materials[] = {"lambert", "phong"};
    printf("\n%s: finest stripe at the camera's limit\n\n"
           "| object | material | finest stripe, camera px | lit px | valid | more than +-1 column "
           "off | of those, off every column under the pixel's 3x3 footprint | depth RMS mm | "
           "points > 2 mm | view ms | rejected as |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|\n",
           config);
    for (size_t o = 0; o < sizeof(objects) / sizeof(objects[0]); o++)
        for (size_t m = 0; m < sizeof(materials) / sizeof(materials[0]); m++) {
            struct view_quality q;
            double ms;
            if (measure_one(config, objects[o], materials[m], 1, &q, &ms) != 0)
                return 1;
            printf("| %s | %s | %.2f | %u | %.2f%% | %.3f%% | %.3f%% | %.3f | %u | %.0f |",
                   shown(objects[o]), materials[m], q.stripe_px, q.lit_head_on,
                   100.0 * q.lit_head_on_valid / q.lit_head_on,
                   100.0 * q.lit_head_on_off / q.lit_head_on,
                   100.0 * q.lit_head_on_wrong / q.lit_head_on, q.depth_rms_mm, q.outliers_2mm, ms);
            for (unsigned r = 1; r < SCAN_REASON_COUNT; r++)
                if (q.head_on_reason[r] > 0)
                    printf(" %s %u", scan_reason_name(r), q.head_on_reason[r]);
            printf(" |\n");
        }
    return 0;
}

/* The third table (issue 16): the very dark paint (albedo 0.03) and saturated highlights, without
 * and with HDR patterns. Highlights: the lit pixels whose white frame at the camera's exposure
 * saturates; Phong with a strong highlight (phong_ks 2). */
static int table_hard(const char *config)
{
    static const uint32_t none[] = {0}, longer[] = {10000, 40000, 0},
                          three[] = {2500, 10000, 40000, 0};
    const uint32_t *sets[] = {none, longer, three};
    const char *names[] = {"none", "10000, 40000", "2500, 10000, 40000"};
    const char *objects[] = {"sphere", "mesh", "torus"};
    printf("\n%s: very dark paint and highlights, HDR patterns ([scan] exposures_us)\n\n"
           "| object | exposures_us | frames | dark paint px | decoded right (+-1) | glossy: "
           "saturated "
           "px | decoded right (+-1) | view ms |\n|---|---|---|---|---|---|---|---|\n",
           config);
    for (size_t o = 0; o < sizeof(objects) / sizeof(objects[0]); o++)
        for (size_t e = 0; e < sizeof(sets) / sizeof(sets[0]); e++) {
            struct view_quality dark, gloss;
            double ms, ms_gloss;
            if (measure_hdr(config, objects[o], "lambert", 1, sets[e], &dark, &ms) != 0 ||
                measure_hdr(config, objects[o], "phong", 1, sets[e], &gloss, &ms_gloss) != 0)
                return 1;
            uint32_t exposures = 0;
            while (sets[e][exposures] != 0)
                exposures++;
            printf("| %s | %s | %u | %u | %.1f%% | %u | %.1f%% | %.0f |\n", shown(objects[o]),
                   names[e], 22u * (exposures ? exposures : 1u), dark.dark,
                   100.0 * dark.dark_correct / (dark.dark ? dark.dark : 1), gloss.saturated,
                   100.0 * gloss.saturated_correct / (gloss.saturated ? gloss.saturated : 1), ms);
        }
    return 0;
}

/* The fourth table (issue 16): a concave scene lit by its own bounced light, direct light alone
 * beside it; every lit pixel counts (a corner has no grazing faces). */
static int table_concave(const char *config)
{
    printf("\n%s: interreflections\n\n| object | code | bounce samples | lit px | valid | wrong "
           "(off every column of its 3x3 footprint) | more than +-1 column off | depth RMS mm | "
           "points > 2 mm | view ms |\n|---|---|---|---|---|---|---|---|---|---|\n",
           config);
    const char *objects[] = {"corner", "groove"};
    for (uint32_t run = 0; run < 8; run++) {
        uint32_t bounce = run & 1u ? 32u : 0u, code = (run >> 1) & 1u;
        static struct test_rig t;
        if (test_rig_load(&t, config) != 0)
            return 1;
        t.cfg.sim.bounce_samples = bounce;
        t.cfg.scan.code = code;
        snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "%s", objects[run >> 2]);
        struct view_quality q;
        double ms;
        if (measure_rig(&t, &q, &ms) != 0)
            return 1;
        printf("| %s | %s | %u | %u | %.2f%% | %.3f%% | %.3f%% | %.3f | %u | %.0f |\n",
               t.cfg.sim.object, code ? "XOR-04" : "Gray", bounce, q.lit,
               100.0 * q.lit_valid / q.lit, 100.0 * q.lit_wrong / q.lit, 100.0 * q.lit_off / q.lit,
               q.depth_rms_mm, q.outliers_2mm, ms);
    }
    return 0;
}

/* measure_view [--inverse-bits N] [CONFIG [LIMIT_CONFIG [HARD_CONFIG [CONCAVE_CONFIG]]]]; "-"
 * leaves a table out. */
int main(int argc, char **argv)
{
    if (argc > 2 && strcmp(argv[1], "--inverse-bits") == 0) {
        inverse_bits = strtol(argv[2], NULL, 10);
        if (inverse_bits < 0 || inverse_bits > 16) {
            fprintf(stderr, "measure_view: --inverse-bits 0..16 (0: every bit)\n");
            return 2;
        }
        printf("Every view with [scan] inverse_bits = %ld\n", inverse_bits);
        argc -= 2;
        argv += 2;
    }
    const char *config = argc > 1 ? argv[1] : "config/sim.ini";
    if (strcmp(config, "-") != 0 && table_objects(config) != 0)
        return 1;
    if (argc > 2 && strcmp(argv[2], "-") != 0 && table_limit(argv[2]) != 0)
        return 1;
    if (argc > 3 && strcmp(argv[3], "-") != 0 && table_hard(argv[3]) != 0)
        return 1;
    return argc > 4 ? table_concave(argv[4]) : 0;
}
