/* Prints decoding rate, depth error and time per view for simulated objects (make measure). */
#define _POSIX_C_SOURCE 200809L
#include "test_util.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

int main(int argc, char **argv)
{
    const char *objects[] = {"sphere", "mesh", "cylinder", "box", "torus"};
    const char *materials[] = {"lambert", "phong"};
    int refine_from = 0, refine_to = 1;
    printf("| object | material | lit px | decoded right (+-1) | same, incidence < 75 deg, not "
           "dark paint | dark paint flagged | valid px | depth RMS mm | RMS / distance | max dist. "
           "to surface mm | "
           "points > 2 mm | normal error deg | refine | view ms |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (size_t o = 0; o < sizeof(objects) / sizeof(objects[0]); o++) {
        for (size_t m = 0; m < sizeof(materials) / sizeof(materials[0]); m++)
            for (int refine = refine_from; refine <= refine_to; refine++) {
                static struct test_rig t;
                if (test_rig_load(&t, argc > 1 ? argv[1] : "config/sim.ini") != 0)
                    return 1;
                snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "%s", objects[o]);
                snprintf(t.cfg.sim.material, sizeof(t.cfg.sim.material), "%s", materials[m]);
                t.cfg.scan.refine = (uint32_t)refine;
                if (test_rig_start(&t) != 0)
                    return 1;
                struct scan_view view;
                struct scan_view_info info;
                double t0 = now_ms();
                int rc = scan_take_view(&t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &info);
                double ms = now_ms() - t0;
                if (rc != 0)
                    return 1;
                struct view_quality q;
                test_measure_view(sim_ctl_rig(), &view, &q);
                printf("| %s | %s | %u | %.2f%% | %.2f%% | %u of %u | %u | %.3f | %.3f%% | %.2f | "
                       "%u | "
                       "%.1f | %s | %.0f |\n",
                       strcmp(objects[o], "mesh") == 0 ? "bunny" : objects[o], materials[m], q.lit,
                       100.0 * q.lit_correct / q.lit, 100.0 * q.lit_head_on_correct / q.lit_head_on,
                       q.dark_flagged, q.dark, q.valid, q.depth_rms_mm,
                       100.0 * q.depth_rms_mm / q.distance_mm, q.max_surface_mm, q.outliers_2mm,
                       q.normal_err_deg, refine ? "on" : "off", ms);
                test_rig_stop(&t);
            }
    }
    return 0;
}
