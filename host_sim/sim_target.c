/* Calibration targets for the simulator: the board's plate and sheet, the matte sphere. */
#include "sim_target.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>

#define PAPER_WHITE 0.85 /* reflectance of the sheet's white; its black is 0.04 */
#define PAPER_BLACK 0.04

int sim_target_mesh(const struct sim_target *t, struct sim_mesh *m, struct sim_sheet_frame *f)
{
    if (t->kind == SIM_TARGET_SPHERE) {
        int rc = sim_mesh_sphere(m, 0.5 * t->diameter_mm, 512);
        if (rc != 0)
            return rc;
        for (uint32_t i = 0; i < m->vert_count; i++) { /* resting on the table at its foot */
            m->pos[3 * i] += (float)t->position_mm[0];
            m->pos[3 * i + 1] += (float)t->position_mm[1];
            m->pos[3 * i + 2] += (float)(0.5 * t->diameter_mm);
        }
        return 0;
    }
    if (t->kind != SIM_TARGET_BOARD || t->sheet == NULL || t->sheet_px_per_mm <= 0.0)
        return -EINVAL;
    const double w = t->sheet_width / t->sheet_px_per_mm, h = t->sheet_height / t->sheet_px_per_mm;
    const double th = t->thickness_mm, tilt = t->tilt_deg * M_PI / 180.0;
    /* Upright, the face looks at the camera (+x) and the sheet's rows run along +y (the camera's
     * right); leaning back turns the face up about the plate's bottom edge. */
    const vec3 up = v3(-sin(tilt), 0.0, cos(tilt)), n = v3(cos(tilt), 0.0, sin(tilt));
    const vec3 across = v3(0.0, 1.0, 0.0);
    const vec3 base = v3(t->position_mm[0], t->position_mm[1], 0.0);
    int rc = sim_mesh_box(m, th, w, h, 4); /* x in +-th/2, y in +-w/2, z in 0..h */
    if (rc != 0)
        return rc;
    for (uint32_t i = 0; i < m->vert_count; i++) {
        float *p = &m->pos[3 * i];
        vec3 q = v3_add(base, v3_add(v3_scale(n, p[0] + 0.5 * th),
                                     v3_add(v3_scale(across, p[1]), v3_scale(up, p[2]))));
        p[0] = (float)q.x;
        p[1] = (float)q.y;
        p[2] = (float)q.z;
    }
    sim_mesh_compute_normals(m);
    f->n = n;
    f->ex = across;
    f->ey = v3_scale(up, -1.0);
    f->origin =
        v3_add(base, v3_add(v3_scale(n, th), v3_add(v3_scale(across, -0.5 * w), v3_scale(up, h))));
    return 0;
}

static double texel(const struct sim_target *t, long x, long y)
{
    if (x < 0 || y < 0 || x >= (long)t->sheet_width || y >= (long)t->sheet_height)
        return PAPER_WHITE; /* the plate around the sheet */
    double g = t->sheet[(size_t)y * t->sheet_width + (size_t)x] / 255.0;
    return PAPER_BLACK + (PAPER_WHITE - PAPER_BLACK) * g;
}

double sim_target_sheet_albedo(const struct sim_target *t, const struct sim_sheet_frame *f,
                               const vec3 *points, uint32_t n_samples)
{
    double sum = 0.0;
    for (uint32_t k = 0; k < n_samples; k++) {
        vec3 d = v3_sub(points[k], f->origin);
        /* texel centres at integers + 0.5 of the sheet's pixel grid */
        double x = v3_dot(d, f->ex) * t->sheet_px_per_mm - 0.5;
        double y = v3_dot(d, f->ey) * t->sheet_px_per_mm - 0.5;
        long x0 = (long)floor(x), y0 = (long)floor(y);
        double ax = x - x0, ay = y - y0;
        sum += (1 - ay) * ((1 - ax) * texel(t, x0, y0) + ax * texel(t, x0 + 1, y0)) +
               ay * ((1 - ax) * texel(t, x0, y0 + 1) + ax * texel(t, x0 + 1, y0 + 1));
    }
    return sum / n_samples;
}
