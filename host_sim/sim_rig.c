/* Simulated rig renderer: ray-cast geometry once per angle, then cheap per-frame shading + noise.
 */
#define _POSIX_C_SOURCE 200809L
#include "sim_rig.h"

#include "camray.h"
#include "frames.h"
#include "gray.h"
#include "lens.h"
#include "sim_jpeg.h"
#include "sim_random.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GAUSS_TABLE 65536u

static void fill_gauss(float *table, uint64_t seed)
{
    /* Box-Muller pairs; indexing this table with random bits is much faster than logs per pixel. */
    for (uint32_t i = 0; i < GAUSS_TABLE; i += 2) {
        double u1 = 1.0 - sim_random_unit(&seed); /* (0, 1]: log() must not see 0 */
        double u2 = sim_random_unit(&seed);
        double r = sqrt(-2.0 * log(u1));
        table[i] = (float)(r * cos(2.0 * M_PI * u2));
        table[i + 1] = (float)(r * sin(2.0 * M_PI * u2));
    }
}

int sim_albedo_at(const struct sim_config *cfg, double height_mm, vec3 p, double albedo[3])
{
    static const double palette[5][3] = {
        {0.80, 0.78, 0.70}, /* ivory */
        {0.70, 0.15, 0.12}, /* red */
        {0.18, 0.55, 0.22}, /* green */
        {0.15, 0.22, 0.65}, /* blue */
        {0.85, 0.70, 0.15}, /* yellow */
    };
    if (strcmp(cfg->albedo_pattern, "uniform") == 0) {
        memcpy(albedo, cfg->albedo, 3 * sizeof(double));
        return 0;
    }
    double az = atan2(p.y, p.x);
    if (az < 0.0)
        az += 2.0 * M_PI;
    if (strcmp(cfg->albedo_pattern, "image") == 0) {
        double v = 1.0 - p.z / height_mm;
        sim_albedo_image_at(az / (2.0 * M_PI), v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v, albedo);
        return 0;
    }
    int sector = (int)(az / (M_PI / 4.0)) % 8;
    double h = p.z / height_mm;
    int band = h < 0.0 ? 0 : (h >= 1.0 ? 4 : (int)(h * 5.0));
    /* A narrow stripe of very dark paint, facing the camera at angle 0. */
    if (sector == 0 && h >= 0.50 && h < 0.53) {
        albedo[0] = albedo[1] = albedo[2] = 0.03;
        return 1;
    }
    memcpy(albedo, palette[(sector + 3 * band) % 5], 3 * sizeof(double));
    return 0;
}

double sim_rig_placed_height(const struct sim_config *cfg)
{
    return strcmp(cfg->object, "torus") == 0 ? 0.28 * cfg->object_height_mm : cfg->object_height_mm;
}

/* [sim] object_pose: turn the standing object (R = Rz Ry Rx), then stand it on the table again,
 * centred on the axis at its lowest point, and [sim] object_offset_mm from it; the paint stays
 * on the object (sim_albedo_at is asked in the standing frame, q = R^T (p - shift)). */
static void pose_object(struct sim_rig *rig)
{
    const double *d = rig->cfg.object_pose_deg;
    double a = d[0] * M_PI / 180.0, b = d[1] * M_PI / 180.0, g = d[2] * M_PI / 180.0;
    double rx[9] = {1, 0, 0, 0, cos(a), -sin(a), 0, sin(a), cos(a)};
    double ry[9] = {cos(b), 0, sin(b), 0, 1, 0, -sin(b), 0, cos(b)};
    double rz[9] = {cos(g), -sin(g), 0, sin(g), cos(g), 0, 0, 0, 1};
    double t[9], *r = rig->pose_rot;
    m3_mul_m3(ry, rx, t);
    m3_mul_m3(rz, t, r);
    const double *off = rig->cfg.object_offset_mm;
    rig->pose_shift = v3(0, 0, 0);
    if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0 && off[0] == 0.0 && off[1] == 0.0)
        return; /* standing as it is, on the axis: the mesh is not touched */
    struct sim_mesh *m = &rig->mesh;
    vec3 lo = v3(1e30, 1e30, 1e30), hi = v3(-1e30, -1e30, -1e30);
    for (uint32_t i = 0; i < m->vert_count; i++) {
        float *p = &m->pos[3 * i];
        vec3 q = m3_mul(r, v3(p[0], p[1], p[2]));
        lo = v3(fmin(lo.x, q.x), fmin(lo.y, q.y), fmin(lo.z, q.z));
        hi = v3(fmax(hi.x, q.x), fmax(hi.y, q.y), fmax(hi.z, q.z));
    }
    rig->pose_shift = v3(off[0] - 0.5 * (lo.x + hi.x), off[1] - 0.5 * (lo.y + hi.y), -lo.z);
    for (uint32_t i = 0; i < m->vert_count; i++) {
        float *p = &m->pos[3 * i];
        vec3 q = v3_add(m3_mul(r, v3(p[0], p[1], p[2])), rig->pose_shift);
        p[0] = (float)q.x, p[1] = (float)q.y, p[2] = (float)q.z;
    }
    sim_mesh_compute_normals(m);
}

static int build_object(struct sim_rig *rig, const char *dir, char *err, size_t len)
{
    const struct sim_config *c = &rig->cfg;
    double h = c->object_height_mm;
    int rc;
    if (strcmp(c->object, "sphere") == 0)
        rc = sim_mesh_sphere(&rig->mesh, 0.5 * h, c->segments);
    else if (strcmp(c->object, "cylinder") == 0)
        rc = sim_mesh_cylinder(&rig->mesh, 0.3 * h, h, c->segments);
    else if (strcmp(c->object, "can") == 0)
        rc = sim_mesh_can(&rig->mesh, 0.3 * h, h, c->segments);
    else if (strcmp(c->object, "box") == 0)
        rc = sim_mesh_box(&rig->mesh, 0.6 * h, 0.45 * h, h, c->segments);
    else if (strcmp(c->object, "corner") == 0)
        rc = sim_mesh_corner(&rig->mesh, h, c->segments);
    else if (strcmp(c->object, "groove") == 0)
        rc = sim_mesh_groove(&rig->mesh, h, 60.0, c->segments);
    else if (strcmp(c->object, "torus") == 0) /* lying flat: h is its outer diameter */
        rc = sim_mesh_torus(&rig->mesh, 0.36 * h, 0.14 * h, c->segments);
    else {
        char path[HAL_MAX_PATH * 2];
        snprintf(path, sizeof(path), "%s%s%s", c->mesh_file[0] == '/' ? "" : dir,
                 c->mesh_file[0] == '/' ? "" : "/", c->mesh_file);
        rc = sim_mesh_load_ply(&rig->mesh, path, err, (unsigned)len);
        if (rc != 0)
            return rc;
        sim_mesh_y_up_to_z_up(&rig->mesh);
    }
    if (rc != 0) {
        snprintf(err, len, "sim: cannot build the %s: %s", c->object, strerror(-rc));
        return rc;
    }
    rig->object_height_mm = sim_rig_placed_height(c);
    sim_mesh_place(&rig->mesh, rig->object_height_mm);
    pose_object(rig);
    return 0;
}

static int build_material(struct sim_rig *rig, const char *dir, char *err, size_t len)
{
    const struct sim_config *c = &rig->cfg;
    memset(&rig->material, 0, sizeof(rig->material));
    if (strcmp(c->material, "lambert") == 0) {
        rig->material.kind = SIM_MAT_LAMBERT;
    } else if (strcmp(c->material, "burley") == 0) {
        rig->material.kind = SIM_MAT_BURLEY;
        rig->material.roughness = c->burley_roughness;
    } else if (strcmp(c->material, "phong") == 0) {
        rig->material.kind = SIM_MAT_PHONG;
        rig->material.ks = c->phong_ks;
        rig->material.ke = c->phong_ke;
    } else {
        char path[HAL_MAX_PATH * 2];
        snprintf(path, sizeof(path), "%s%s%s", c->merl_file[0] == '/' ? "" : dir,
                 c->merl_file[0] == '/' ? "" : "/", c->merl_file);
        int rc = sim_material_load_abc(&rig->material, path, c->merl_name);
        if (rc != 0) {
            snprintf(err, len, "sim: material '%s' from %s: %s", c->merl_name, path,
                     rc == -ESRCH ? "not in the table" : strerror(-rc));
            return rc;
        }
    }
    return 0;
}

int sim_rig_init(struct sim_rig *rig, const struct sim_config *cfg, const struct scan_calib *calib,
                 const struct gray_layout *layout, const char *dir, char *err, size_t len)
{
    memset(rig, 0, sizeof(*rig));
    rig->cfg = *cfg;
    rig->calib = *calib;
    rig->width = calib->cam_width;
    rig->height = calib->cam_height;
    rig->layout = *layout;
    snprintf(rig->dir, sizeof(rig->dir), "%s", dir);
    rig->table_angle_mdeg = 0; /* the turntable, when there is one, sets it per frame */
    int rc = build_object(rig, dir, err, len);
    if (rc == 0)
        rc = build_material(rig, dir, err, len);
    if (rc == 0)
        rc = sim_bvh_build(&rig->bvh, &rig->mesh);
    if (rc != 0)
        goto out_free;
    size_t n = (size_t)rig->width * rig->height;
    struct sim_truth *t = &rig->truth;
    t->hit = calloc(n, 1);
    t->pos_cam = calloc(n * 3, sizeof(float));
    t->normal_cam = calloc(n * 3, sizeof(float));
    t->albedo = calloc(n * 3, sizeof(float));
    t->proj_u = calloc(n, sizeof(float));
    t->proj_v = calloc(n, sizeof(float));
    t->proj_lit = calloc(n, 1);
    t->dark = calloc(n, 1);
    rig->proj_radiance = calloc(n * 3, sizeof(float));
    rig->light_vis = calloc(n, 1);
    rig->gauss = calloc(GAUSS_TABLE, sizeof(float));
    rig->signal = calloc(n * 3, sizeof(float));
    rig->bounce_w = (rig->width + SIM_BOUNCE_STEP - 1) / SIM_BOUNCE_STEP + 1;
    rig->bounce_h = (rig->height + SIM_BOUNCE_STEP - 1) / SIM_BOUNCE_STEP + 1;
    size_t samples = (size_t)rig->bounce_w * rig->bounce_h * cfg->bounce_samples;
    if (samples > 0) {
        rig->bounce_u = calloc(samples, sizeof(float));
        rig->bounce_v = calloc(samples, sizeof(float));
        rig->bounce_rad = calloc(samples * 3, sizeof(float));
        rig->bounce_light = calloc((size_t)rig->bounce_w * rig->bounce_h * 3, sizeof(float));
        if (!rig->bounce_u || !rig->bounce_v || !rig->bounce_rad || !rig->bounce_light) {
            rc = -ENOMEM;
            snprintf(err, len, "sim: out of memory for %u bounce samples", cfg->bounce_samples);
            goto out_free;
        }
    }
    rig->blur_line =
        calloc((size_t)3 * (rig->width > rig->height ? rig->width : rig->height), sizeof(float));
    if (!t->hit || !t->pos_cam || !t->normal_cam || !t->albedo || !t->proj_u || !t->proj_v ||
        !t->proj_lit || !t->dark || !rig->proj_radiance || !rig->light_vis || !rig->gauss ||
        !rig->signal || !rig->blur_line) {
        rc = -ENOMEM;
        snprintf(err, len, "sim: out of memory for a %ux%u frame", (unsigned)rig->width,
                 (unsigned)rig->height);
        goto out_free;
    }
    fill_gauss(rig->gauss, 0x5ca77e5ull ^ cfg->seed);
    return 0;
out_free:
    sim_rig_free(rig);
    return rc;
}

void sim_rig_free(struct sim_rig *rig)
{
    struct sim_truth *t = &rig->truth;
    free(t->hit);
    free(t->pos_cam);
    free(t->normal_cam);
    free(t->albedo);
    free(t->proj_u);
    free(t->proj_v);
    free(t->proj_lit);
    free(t->dark);
    free(rig->proj_radiance);
    free(rig->light_vis);
    free(rig->gauss);
    free(rig->signal);
    free(rig->bounce_u);
    free(rig->bounce_v);
    free(rig->bounce_rad);
    free(rig->bounce_light);
    free(rig->blur_line);
    sim_bvh_free(&rig->bvh);
    sim_mesh_free(&rig->mesh);
    free(rig->sheet_pixels);
    memset(rig, 0, sizeof(*rig));
}

int sim_rig_set_target(struct sim_rig *rig, const struct sim_target *t, char *err, size_t len)
{
    struct sim_mesh mesh;
    struct sim_bvh bvh;
    struct sim_sheet_frame sheet;
    uint8_t *pixels = NULL;
    int rc;
    memset(&sheet, 0, sizeof(sheet));
    if (t->kind == SIM_TARGET_OBJECT) {
        struct sim_mesh old = rig->mesh;
        rc = build_object(rig, rig->dir, err, len);
        if (rc != 0) {
            rig->mesh = old;
            return rc;
        }
        mesh = rig->mesh;
        rig->mesh = old;
    } else if ((rc = sim_target_mesh(t, &mesh, &sheet)) != 0) {
        snprintf(err, len, "sim: cannot build the calibration target: %s", strerror(-rc));
        return rc;
    }
    if (t->kind == SIM_TARGET_BOARD) {
        size_t n = (size_t)t->sheet_width * t->sheet_height;
        pixels = malloc(n);
        if (pixels == NULL) {
            sim_mesh_free(&mesh);
            snprintf(err, len, "sim: out of memory for the board's sheet");
            return -ENOMEM;
        }
        memcpy(pixels, t->sheet, n);
    }
    if ((rc = sim_bvh_build(&bvh, &mesh)) != 0) {
        free(pixels);
        sim_mesh_free(&mesh);
        snprintf(err, len, "sim: cannot build the target's ray-casting tree: %s", strerror(-rc));
        return rc;
    }
    sim_bvh_free(&rig->bvh);
    sim_mesh_free(&rig->mesh);
    free(rig->sheet_pixels);
    rig->mesh = mesh;
    rig->bvh = bvh;
    rig->bvh.mesh = &rig->mesh; /* it was built over the local copy */
    rig->sheet = sheet;
    rig->sheet_pixels = pixels;
    rig->target = *t;
    rig->target.sheet = pixels;
    /* Targets are matte; the object keeps its configured material. */
    if (t->kind == SIM_TARGET_OBJECT)
        rc = build_material(rig, rig->dir, err, len);
    else
        memset(&rig->material, 0, sizeof(rig->material)); /* SIM_MAT_LAMBERT */
    rig->truth_valid = 0;
    return rc;
}

static vec3 projector_centre_cam(const struct scan_calib *c)
{
    /* p_proj = R p_cam + t, so the projector centre (p_proj = 0) is -R^T t. */
    return v3_scale(m3_tmul(c->proj_rot, v3_from(c->proj_trans_mm)), -1.0);
}

/* Is the segment from @p p_obj (on the surface, normal @p n_obj) to @p src_obj blocked? */
static int occluded(const struct sim_rig *rig, vec3 p_obj, vec3 n_obj, vec3 src_obj)
{
    vec3 start = v3_add(p_obj, v3_scale(n_obj, 0.01)); /* 10 um off the surface */
    return sim_bvh_occluded(&rig->bvh, start, v3_sub(src_obj, start), 1e-6, 1.0 - 1e-6);
}

#define DIFFUSER_SAMPLES 32

static double falloff(const struct sim_rig *rig, double dist_mm)
{
    double r = rig->cfg.reference_distance_mm / dist_mm;
    return r * r; /* inverse-square law, 1 at the reference distance */
}

#define SHEET_SAMPLES 8 /* per pixel side: a camera pixel integrates the print over its area */
#define PAINT_SAMPLES 4 /* per pixel side: the same for an object's paint */

/* Where the sub-pixel rays of the pixel whose ray is @p d_cam (camera frame, z = 1) meet the
 * plane through @p origin facing @p n (object frame): @p side x @p side rays spread evenly over
 * the pixel, the lens linearised about the pixel's ray. @retval the points written to @p pts */
static uint32_t footprint_on_plane(const struct sim_rig *rig, const struct frame_xform *obj,
                                   vec3 cam_obj, vec3 d_cam, vec3 origin, vec3 n, int side,
                                   vec3 *pts)
{
    const struct scan_calib *c = &rig->calib;
    double j[4] = {1, 0, 0, 1}, inv[4];
    if (!lens_is_pinhole(c->cam_dist))
        lens_jacobian(c->cam_dist, d_cam.x, d_cam.y, j);
    double det = j[0] * j[3] - j[1] * j[2];
    inv[0] = j[3] / det, inv[1] = -j[1] / det, inv[2] = -j[2] / det, inv[3] = j[0] / det;
    uint32_t count = 0;
    for (int sy = 0; sy < side; sy++) {
        for (int sx = 0; sx < side; sx++) {
            double dx = ((sx + 0.5) / side - 0.5) / c->cam_fx_px;
            double dy = ((sy + 0.5) / side - 0.5) / c->cam_fy_px;
            vec3 d =
                v3(d_cam.x + inv[0] * dx + inv[1] * dy, d_cam.y + inv[2] * dx + inv[3] * dy, 1.0);
            vec3 dir = frame_dir(obj, d);
            double den = v3_dot(dir, n);
            if (den == 0.0)
                continue;
            double s = v3_dot(v3_sub(origin, cam_obj), n) / den;
            pts[count++] = v3_add(cam_obj, v3_scale(dir, s));
        }
    }
    return count;
}

/* Albedo of a calibration target at p_obj. On the board's face, the sheet averaged over the
 * pixel's footprint (footprint_on_plane); a single ray per pixel would put every printed edge
 * on the pixel grid. */
static void target_albedo(const struct sim_rig *rig, const struct frame_xform *obj, vec3 cam_obj,
                          vec3 d_cam, vec3 p_obj, double albedo[3])
{
    const struct sim_sheet_frame *f = &rig->sheet;
    double a = 0.9; /* the matte white sphere, the plate's edges */
    if (rig->target.kind == SIM_TARGET_BOARD &&
        fabs(v3_dot(v3_sub(p_obj, f->origin), f->n)) < 0.01) {
        vec3 pts[SHEET_SAMPLES * SHEET_SAMPLES];
        uint32_t n =
            footprint_on_plane(rig, obj, cam_obj, d_cam, f->origin, f->n, SHEET_SAMPLES, pts);
        a = n > 0 ? sim_target_sheet_albedo(&rig->target, f, pts, n) : a;
    }
    albedo[0] = albedo[1] = albedo[2] = a;
}

/* A surface point in both frames. */
struct surface_point {
    vec3 p_cam, n_cam, p_obj, n_obj;
};

/* Where @p sp falls in the projector image (u, v: NAN behind it), and the light it sends
 * towards @p to_viewer (camera frame, unit) under the projector's full white, in grey levels.
 * @retval 1 the projector lights it (in its image, facing it, not shadowed) @retval 0 not */
static int projector_light(const struct sim_rig *rig, const struct surface_point *sp, vec3 proj_cam,
                           vec3 proj_obj, const double albedo[3], vec3 to_viewer, double *u,
                           double *v, double rad[3])
{
    const struct scan_calib *c = &rig->calib;
    rad[0] = rad[1] = rad[2] = 0.0;
    *u = *v = NAN;
    if (!camray_project_projector(c, sp->p_cam, u, v))
        return 0;
    vec3 to_proj = v3_sub(proj_cam, sp->p_cam);
    vec3 l = v3_norm(to_proj);
    if (*u < -0.5 || *u >= c->proj_width - 0.5 || *v < -0.5 || *v >= c->proj_height - 0.5 ||
        v3_dot(sp->n_cam, l) <= 0.0 || occluded(rig, sp->p_obj, sp->n_obj, proj_obj))
        return 0;
    double rho[3];
    sim_material_eval(&rig->material, albedo, sp->n_cam, l, to_viewer, rho);
    double e = rig->cfg.projector_intensity_dn * falloff(rig, v3_len(to_proj));
    for (int k = 0; k < 3; k++)
        rad[k] = e * rho[k];
    return 1;
}

/* The surface point of a ray hit, object frame: position, shading normal. */
static void hit_point(const struct sim_mesh *m, const struct sim_hit *hit, vec3 *p, vec3 *n)
{
    const uint32_t *tv = &m->tri[3 * hit->tri];
    double w[3] = {1.0 - hit->u - hit->v, hit->u, hit->v};
    *p = v3(0, 0, 0);
    *n = v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        const float *pn = &m->normal[3 * tv[k]], *pp = &m->pos[3 * tv[k]];
        *n = v3_add(*n, v3_scale(v3(pn[0], pn[1], pn[2]), w[k]));
        *p = v3_add(*p, v3_scale(v3(pp[0], pp[1], pp[2]), w[k]));
    }
    *n = v3_norm(*n);
}

/* The object's paint at @p p_obj (as placed), asked in its standing frame, where it was laid
 * out. @retval 1 the very dark paint, 0 not */
static int object_albedo(const struct sim_rig *rig, vec3 p_obj, double albedo[3])
{
    return sim_albedo_at(&rig->cfg, rig->object_height_mm,
                         m3_tmul(rig->pose_rot, v3_sub(p_obj, rig->pose_shift)), albedo);
}

/* The object's paint as the pixel whose ray is @p d_cam sees it: averaged over the pixel's
 * footprint on the surface's tangent plane at the hit (@p p_obj, @p n_obj), as a camera pixel
 * integrates the light over its area. A single ray per pixel put every paint boundary on the
 * pixel grid: up to half a pixel (0.17 mm at 600 mm) off where it is, the same way in every
 * frame of a view, and views seeing the paint from opposite sides disagreed by twice that
 * where the colour is all that places them (issue 30: a box pushed 30 mm, placed by its
 * paint 0.15 to 0.35 mm off). @retval 1 the pixel sees the very dark paint alone (at its edges
 * a pixel mixes it with the paint beside it, brighter) */
static int object_paint(const struct sim_rig *rig, const struct frame_xform *obj, vec3 cam_obj,
                        vec3 d_cam, vec3 p_obj, vec3 n_obj, double albedo[3])
{
    vec3 pts[PAINT_SAMPLES * PAINT_SAMPLES];
    uint32_t n = footprint_on_plane(rig, obj, cam_obj, d_cam, p_obj, n_obj, PAINT_SAMPLES, pts);
    if (n == 0) /* the ray along the plane: the paint at the hit */
        return object_albedo(rig, p_obj, albedo);
    int dark = 1;
    double sum[3] = {0.0, 0.0, 0.0};
    for (uint32_t k = 0; k < n; k++) {
        double a[3];
        dark &= object_albedo(rig, pts[k], a);
        for (int c = 0; c < 3; c++)
            sum[c] += a[c];
    }
    for (int c = 0; c < 3; c++)
        albedo[c] = sum[c] / n;
    return dark;
}

/* Cast the camera ray of pixel (x, y); fill truth and the projector's reflected light. */
static void update_pixel(struct sim_rig *rig, const struct frame_xform *obj, vec3 cam_obj,
                         vec3 proj_cam, vec3 proj_obj, uint32_t x, uint32_t y)
{
    const struct scan_calib *c = &rig->calib;
    struct sim_truth *t = &rig->truth;
    size_t i = (size_t)y * rig->width + x;
    vec3 d_cam = v3(((double)x - c->cam_cx_px) / c->cam_fx_px,
                    ((double)y - c->cam_cy_px) / c->cam_fy_px, 1.0);
    t->hit[i] = 0;
    t->proj_lit[i] = 0;
    t->dark[i] = 0;
    for (int k = 0; k < 3; k++)
        rig->proj_radiance[3 * i + k] = 0.0f;
    if (!lens_is_pinhole(c->cam_dist) &&
        lens_undistort(c->cam_dist, d_cam.x, d_cam.y, &d_cam.x, &d_cam.y) != 0)
        return; /* beyond where the lens model holds: no light reaches this pixel */
    struct sim_hit hit;
    t->hit[i] =
        (uint8_t)sim_bvh_intersect(&rig->bvh, cam_obj, frame_dir(obj, d_cam), 1e-6, 1e9, &hit);
    if (!t->hit[i])
        return;
    vec3 p_obj, n_obj;
    hit_point(&rig->mesh, &hit, &p_obj, &n_obj);
    vec3 p_cam = v3_scale(d_cam, hit.t);
    vec3 n_cam = frame_dir_inv(obj, n_obj);
    double albedo[3];
    if (rig->target.kind == SIM_TARGET_OBJECT)
        t->dark[i] = (uint8_t)object_paint(rig, obj, cam_obj, d_cam, p_obj, n_obj, albedo);
    else
        target_albedo(rig, obj, cam_obj, d_cam, p_obj, albedo);
    for (int k = 0; k < 3; k++) {
        t->albedo[3 * i + k] = (float)albedo[k];
        t->pos_cam[3 * i + k] = (float)(k == 0 ? p_cam.x : k == 1 ? p_cam.y : p_cam.z);
        t->normal_cam[3 * i + k] = (float)(k == 0 ? n_cam.x : k == 1 ? n_cam.y : n_cam.z);
    }
    struct surface_point sp = {p_cam, n_cam, p_obj, n_obj};
    double u, v, rad[3];
    t->proj_lit[i] = (uint8_t)projector_light(rig, &sp, proj_cam, proj_obj, albedo,
                                              v3_norm(v3_scale(p_cam, -1.0)), &u, &v, rad);
    t->proj_u[i] = (float)u;
    t->proj_v[i] = (float)v;
    for (int k = 0; k < 3; k++)
        rig->proj_radiance[3 * i + k] = (float)rad[k];
}

static double pattern_light(const struct sim_rig *rig, uint32_t pattern, double u, double v);

/* ---- one bounce of the projector's light between surfaces ([sim] bounce_samples) ---- */

/* For every grid point (every SIM_BOUNCE_STEP-th pixel each way) on the object: what the surface
 * around it sees in bounce_samples cosine-weighted directions, where that is in the projector
 * image and how much of the projector's full white it sends back (towards the grid point). Once
 * per angle; sim_rig_render adds pattern x that, times the albedo, to every pixel. */
static void bounce_update(struct sim_rig *rig, const struct frame_xform *obj, vec3 proj_cam,
                          vec3 proj_obj)
{
    const uint32_t k_count = rig->cfg.bounce_samples;
    uint64_t state = 0xb0b0ull ^ rig->cfg.seed;
    for (uint32_t gy = 0; gy < rig->bounce_h; gy++)
        for (uint32_t gx = 0; gx < rig->bounce_w; gx++) {
            size_t g = (size_t)gy * rig->bounce_w + gx;
            uint32_t x = gx * SIM_BOUNCE_STEP < rig->width ? gx * SIM_BOUNCE_STEP : rig->width - 1;
            uint32_t y =
                gy * SIM_BOUNCE_STEP < rig->height ? gy * SIM_BOUNCE_STEP : rig->height - 1;
            size_t i = (size_t)y * rig->width + x;
            for (uint32_t k = 0; k < k_count; k++)
                rig->bounce_u[g * k_count + k] = NAN;
            if (!rig->truth.hit[i] || rig->target.kind != SIM_TARGET_OBJECT)
                continue;
            const float *pc = &rig->truth.pos_cam[3 * i], *nc = &rig->truth.normal_cam[3 * i];
            vec3 p_cam = v3(pc[0], pc[1], pc[2]);
            vec3 p_obj = frame_point(obj, p_cam), n_obj = frame_dir(obj, v3(nc[0], nc[1], nc[2]));
            vec3 e1 = v3_norm(v3_cross(n_obj, fabs(n_obj.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0)));
            vec3 e2 = v3_cross(n_obj, e1);
            vec3 start = v3_add(p_obj, v3_scale(n_obj, 0.01));
            for (uint32_t k = 0; k < k_count; k++) {
                double phi = 2.0 * M_PI * sim_random_unit(&state), r2 = sim_random_unit(&state);
                double sr = sqrt(r2); /* cosine-weighted: pdf cos / pi */
                vec3 dir = v3_add(v3_add(v3_scale(e1, sr * cos(phi)), v3_scale(e2, sr * sin(phi))),
                                  v3_scale(n_obj, sqrt(1.0 - r2)));
                struct sim_hit hit;
                if (!sim_bvh_intersect(&rig->bvh, start, dir, 1e-6, 1e9, &hit))
                    continue;
                struct surface_point q;
                hit_point(&rig->mesh, &hit, &q.p_obj, &q.n_obj);
                if (v3_dot(q.n_obj, dir) >= 0.0)
                    continue; /* the back of a face */
                q.p_cam = frame_point_inv(obj, q.p_obj);
                q.n_cam = frame_dir_inv(obj, q.n_obj);
                double albedo[3], u, v, rad[3];
                object_albedo(rig, q.p_obj, albedo);
                if (!projector_light(rig, &q, proj_cam, proj_obj, albedo,
                                     v3_norm(v3_sub(p_cam, q.p_cam)), &u, &v, rad))
                    continue;
                rig->bounce_u[g * k_count + k] = (float)u;
                rig->bounce_v[g * k_count + k] = (float)v;
                for (int c = 0; c < 3; c++)
                    rig->bounce_rad[3 * (g * k_count + k) + (size_t)c] = (float)(rad[c] / k_count);
            }
        }
}

/* This frame's bounced light at every grid point (before the receiving albedo). */
static void bounce_frame(struct sim_rig *rig, uint32_t pattern)
{
    const uint32_t k_count = rig->cfg.bounce_samples;
    size_t grid = (size_t)rig->bounce_w * rig->bounce_h;
    for (size_t g = 0; g < grid; g++) {
        double sum[3] = {0, 0, 0};
        for (uint32_t k = 0; k < k_count; k++) {
            size_t s = g * k_count + k;
            if (isnan(rig->bounce_u[s]))
                continue;
            double p = pattern_light(rig, pattern, rig->bounce_u[s], rig->bounce_v[s]);
            for (int c = 0; c < 3; c++)
                sum[c] += p * rig->bounce_rad[3 * s + (size_t)c];
        }
        for (int c = 0; c < 3; c++)
            rig->bounce_light[3 * g + (size_t)c] = (float)sum[c];
    }
}

/* The bounced light at pixel (x, y): bilinear between the grid points that lie on the object. */
static void bounce_at(const struct sim_rig *rig, uint32_t x, uint32_t y, double out[3])
{
    double fx = (double)x / SIM_BOUNCE_STEP, fy = (double)y / SIM_BOUNCE_STEP;
    uint32_t gx = (uint32_t)fx, gy = (uint32_t)fy;
    double ax = fx - gx, ay = fy - gy, wsum = 0.0;
    out[0] = out[1] = out[2] = 0.0;
    for (uint32_t dy = 0; dy <= 1; dy++)
        for (uint32_t dx = 0; dx <= 1; dx++) {
            uint32_t cx = gx + dx < rig->bounce_w ? gx + dx : rig->bounce_w - 1;
            uint32_t cy = gy + dy < rig->bounce_h ? gy + dy : rig->bounce_h - 1;
            uint32_t px = cx * SIM_BOUNCE_STEP < rig->width ? cx * SIM_BOUNCE_STEP : rig->width - 1;
            uint32_t py =
                cy * SIM_BOUNCE_STEP < rig->height ? cy * SIM_BOUNCE_STEP : rig->height - 1;
            if (!rig->truth.hit[(size_t)py * rig->width + px])
                continue;
            double w = (dx ? ax : 1.0 - ax) * (dy ? ay : 1.0 - ay);
            size_t g = (size_t)cy * rig->bounce_w + cx;
            for (int c = 0; c < 3; c++)
                out[c] += w * rig->bounce_light[3 * g + (size_t)c];
            wsum += w;
        }
    for (int c = 0; c < 3 && wsum > 0.0; c++)
        out[c] /= wsum;
}

/* Camera frame to object frame at table angle @p angle_mdeg: the turntable's, and the object
 * moved on the table by [sim] slip_mm once the table has reached slip_at_deg. */
static void object_frame(const struct sim_rig *rig, int32_t angle_mdeg, struct frame_xform *obj)
{
    frame_object_from_camera(&rig->calib, angle_mdeg, obj);
    if (angle_mdeg >= rig->cfg.slip_at_deg * 1000.0) /* p_obj = R (p - o) - s */
        obj->origin = v3_add(obj->origin, m3_tmul(obj->rot, v3_from(rig->cfg.slip_mm)));
}

void sim_rig_update(struct sim_rig *rig)
{
    if (rig->truth_valid && rig->truth_angle_mdeg == rig->table_angle_mdeg)
        return;
    struct frame_xform obj;
    object_frame(rig, rig->table_angle_mdeg, &obj);
    vec3 cam_obj = frame_point(&obj, v3(0, 0, 0));
    vec3 proj_cam = projector_centre_cam(&rig->calib);
    vec3 proj_obj = frame_point(&obj, proj_cam);
    for (uint32_t y = 0; y < rig->height; y++)
        for (uint32_t x = 0; x < rig->width; x++)
            update_pixel(rig, &obj, cam_obj, proj_cam, proj_obj, x, y);
    if (rig->cfg.bounce_samples > 0)
        bounce_update(rig, &obj, proj_cam, proj_obj);
    rig->truth_angle_mdeg = rig->table_angle_mdeg;
    rig->truth_valid = 1;
    rig->lights_done = 0;
}

/* Shadow rays towards light @p li for every visible pixel, once per angle. */
static void ensure_light(struct sim_rig *rig, uint32_t li)
{
    if (rig->lights_done & (1u << li))
        return;
    struct frame_xform obj;
    object_frame(rig, rig->truth_angle_mdeg, &obj);
    vec3 light_obj = frame_point(&obj, v3_from(rig->calib.light_pos_mm[li]));
    size_t n = (size_t)rig->width * rig->height;
    for (size_t i = 0; i < n; i++) {
        rig->light_vis[i] &= (uint8_t) ~(1u << li);
        if (!rig->truth.hit[i])
            continue;
        const float *pc = &rig->truth.pos_cam[3 * i], *nc = &rig->truth.normal_cam[3 * i];
        vec3 p_obj = frame_point(&obj, v3(pc[0], pc[1], pc[2]));
        vec3 n_obj = frame_dir(&obj, v3(nc[0], nc[1], nc[2]));
        if (!occluded(rig, p_obj, n_obj, light_obj))
            rig->light_vis[i] |= (uint8_t)(1u << li);
    }
    rig->lights_done |= 1u << li;
}

/* Light of the current pattern at projector position (u, v): the lens blurs it over a box of
 * projector_blur_px pixels across the stripes (columns for column bits, rows for row bits), and
 * "black" still leaks projector_black_level of white. */
static double pattern_light(const struct sim_rig *rig, uint32_t pattern, double u, double v)
{
    const struct gray_layout *l = &rig->layout;
    int is_row = 0, inverse;
    uint32_t k;
    if (gray_layout_pattern(l, pattern, &is_row, &k, &inverse) != 0)
        is_row = 0; /* white or black */
    double x = is_row ? v : u, b = rig->cfg.projector_blur_px, lo = x - 0.5 * b, hi = x + 0.5 * b;
    int limit = (int)(is_row ? rig->calib.proj_height : rig->calib.proj_width);
    double c0 = floor(lo + 0.5), c1 = floor(hi + 0.5), lit;
#define LIT(c)                                                                                     \
    (((c) < 0 || (c) >= limit)                                                                     \
         ? 0                                                                                       \
         : gray_layout_lit(l, pattern, is_row ? 0u : (uint32_t)(c), is_row ? (uint32_t)(c) : 0u))
    if (c0 == c1 || b <= 0.0) {
        lit = LIT((int)floor(x + 0.5));
    } else {
        double f0 = (c0 + 0.5 - lo) / b;
        lit = f0 * LIT((int)c0) + (1.0 - f0) * LIT((int)c1);
    }
#undef LIT
    double black = rig->cfg.projector_black_level;
    return black + (1.0 - black) * lit;
}

/* Light-i radiance at pixel i of a surface of diffuse colour @p albedo, computed on the fly
 * (light frames are few). A light with a diffuser is a disk of light_diffuser_mm facing the
 * point, sampled at DIFFUSER_SAMPLES points (a Vogel spiral, the same every frame, so no noise
 * is added); its shadow is the centre's (the caller's to judge). */
static void add_light_of(const struct sim_rig *rig, size_t i, uint32_t li, const double albedo[3],
                         double sig[3])
{
    const float *pc = &rig->truth.pos_cam[3 * i], *nc = &rig->truth.normal_cam[3 * i];
    vec3 p = v3(pc[0], pc[1], pc[2]), n = v3(nc[0], nc[1], nc[2]);
    vec3 centre = v3_from(rig->calib.light_pos_mm[li]), view = v3_norm(v3_scale(p, -1.0));
    double radius = rig->cfg.light_diffuser_mm;
    int samples = radius > 0.0 ? DIFFUSER_SAMPLES : 1;
    vec3 axis = v3_norm(v3_sub(centre, p));
    vec3 e1 = v3_norm(v3_cross(axis, fabs(axis.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0)));
    vec3 e2 = v3_cross(axis, e1);
    for (int j = 0; j < samples; j++) {
        double r = radius * sqrt((j + 0.5) / samples), phi = j * 2.39996322972865332; /* golden */
        vec3 src = v3_add(centre, v3_add(v3_scale(e1, r * cos(phi)), v3_scale(e2, r * sin(phi))));
        vec3 to_light = v3_sub(src, p);
        double rho[3];
        sim_material_eval(&rig->material, albedo, n, v3_norm(to_light), view, rho);
        double e = rig->cfg.light_intensity_dn * falloff(rig, v3_len(to_light)) / samples;
        for (int k = 0; k < 3; k++)
            sig[k] += e * rho[k];
    }
}

/* Light-i radiance at pixel i where the light reaches it (the truth's paint). */
static void add_light(const struct sim_rig *rig, size_t i, uint32_t li, double sig[3])
{
    if (!(rig->light_vis[i] & (1u << li)))
        return;
    const float *al = &rig->truth.albedo[3 * i];
    const double albedo[3] = {al[0], al[1], al[2]};
    add_light_of(rig, i, li, albedo, sig);
}

void sim_rig_specular_at(struct sim_rig *rig, size_t i, uint32_t li, double sig[3])
{
    const double none[3] = {0, 0, 0};
    sig[0] = sig[1] = sig[2] = 0.0;
    if (!rig->truth_valid || !rig->truth.hit[i] || li >= rig->calib.light_count)
        return;
    struct frame_xform obj;
    object_frame(rig, rig->truth_angle_mdeg, &obj);
    const float *pc = &rig->truth.pos_cam[3 * i], *nc = &rig->truth.normal_cam[3 * i];
    vec3 p_obj = frame_point(&obj, v3(pc[0], pc[1], pc[2]));
    vec3 n_obj = frame_dir(&obj, v3(nc[0], nc[1], nc[2]));
    if (!occluded(rig, p_obj, n_obj, frame_point(&obj, v3_from(rig->calib.light_pos_mm[li]))))
        add_light_of(rig, i, li, none, sig);
}

/* The light reaching each pixel's sensor (before gain and noise), 3 floats per pixel. */
static void render_signal(struct sim_rig *rig, const struct sim_sources *src, float *signal)
{
    const struct sim_config *c = &rig->cfg;
    uint32_t lights = src->lights_mask;
    size_t n = (size_t)rig->width * rig->height;
    for (size_t i = 0; i < n; i++) {
        double sig[3] = {0, 0, 0};
        if (rig->truth.hit[i]) {
            const float *al = &rig->truth.albedo[3 * i];
            for (int k = 0; k < 3; k++)
                sig[k] = c->ambient_dn * al[k]; /* indirect light: small, from everywhere */
            if (src->projector_on && rig->truth.proj_lit[i]) {
                double p = pattern_light(rig, src->pattern_index, rig->truth.proj_u[i],
                                         rig->truth.proj_v[i]);
                for (int k = 0; k < 3; k++)
                    sig[k] += p * rig->proj_radiance[3 * i + k];
            }
            if (src->projector_on && rig->cfg.bounce_samples > 0) { /* Lambertian receiver */
                double b[3];
                bounce_at(rig, (uint32_t)(i % rig->width), (uint32_t)(i / rig->width), b);
                for (int k = 0; k < 3; k++)
                    sig[k] += b[k] * al[k];
            }
            for (uint32_t li = 0; lights != 0 && li < rig->calib.light_count; li++)
                if (lights & (1u << li))
                    add_light(rig, i, li, sig);
        }
        for (int k = 0; k < 3; k++)
            signal[3 * i + (size_t)k] = (float)sig[k];
    }
}

/* One 1-D pass of the camera's Gaussian blur over @p count lines of @p len pixels, @p stride
 * floats between pixels, @p line_step between lines (edges clamp). */
static void blur_pass(float *buf, float *line, uint32_t count, uint32_t len, size_t stride,
                      size_t line_step, const float *kernel, int radius)
{
    for (uint32_t l = 0; l < count; l++) {
        float *base = buf + l * line_step;
        for (uint32_t x = 0; x < len; x++)
            for (int k = 0; k < 3; k++)
                line[3 * x + (size_t)k] = base[x * stride + (size_t)k];
        for (uint32_t x = 0; x < len; x++) {
            float acc[3] = {0, 0, 0};
            for (int d = -radius; d <= radius; d++) {
                long xs = (long)x + d;
                xs = xs < 0 ? 0 : xs >= (long)len ? (long)len - 1 : xs;
                for (int k = 0; k < 3; k++)
                    acc[k] += kernel[d + radius] * line[3 * (size_t)xs + (size_t)k];
            }
            for (int k = 0; k < 3; k++)
                base[x * stride + (size_t)k] = acc[k];
        }
    }
}

#define BLUR_MAX_RADIUS 16

/* [sim] camera_blur_px: the camera lens's point spread, a Gaussian of that sigma (separable). */
static void camera_blur(struct sim_rig *rig, float *signal)
{
    double sigma = rig->cfg.camera_blur_px;
    int radius = (int)ceil(3.0 * sigma);
    radius = radius > BLUR_MAX_RADIUS ? BLUR_MAX_RADIUS : radius;
    float kernel[2 * BLUR_MAX_RADIUS + 1];
    double sum = 0.0;
    for (int d = -radius; d <= radius; d++)
        sum += kernel[d + radius] = (float)exp(-0.5 * d * d / (sigma * sigma));
    for (int d = -radius; d <= radius; d++)
        kernel[d + radius] = (float)(kernel[d + radius] / sum);
    uint32_t w = rig->width, h = rig->height;
    blur_pass(signal, rig->blur_line, h, w, 3, (size_t)3 * w, kernel, radius);
    blur_pass(signal, rig->blur_line, w, h, (size_t)3 * w, 3, kernel, radius);
}

void sim_rig_render(struct sim_rig *rig, const struct sim_sources *src, uint64_t noise_id,
                    uint8_t *rgb)
{
    sim_rig_update(rig);
    for (uint32_t li = 0; li < rig->calib.light_count; li++)
        if (src->lights_mask & (1u << li))
            ensure_light(rig, li);
    const struct sim_config *c = &rig->cfg;
    float *signal = rig->signal;
    if (src->projector_on && c->bounce_samples > 0)
        bounce_frame(rig, src->pattern_index);
    render_signal(rig, src, signal);
    if (c->camera_blur_px > 0.0)
        camera_blur(rig, signal);
    double gain = (double)src->exposure_us / c->reference_exposure_us * src->gain_milli / 1000.0;
    uint64_t state = ((uint64_t)c->seed << 32) ^ (noise_id * 0x9E3779B97F4A7C15ull) ^
                     (uint64_t)(uint32_t)rig->truth_angle_mdeg;
    double var_read = c->read_noise_dn * c->read_noise_dn;
    size_t n = (size_t)rig->width * rig->height;
    for (size_t i = 0; i < n; i++) {
        uint64_t r = sim_random_next(&state);
        for (int k = 0; k < 3; k++) {
            double s = signal[3 * i + (size_t)k] * gain;
            double sigma = sqrt(var_read + (s > 0.0 ? s / c->electrons_per_dn : 0.0));
            double dn = c->black_offset_dn + s + sigma * rig->gauss[(r >> (16 * k)) & 0xFFFFu];
            dn = floor(dn + 0.5);
            rgb[3 * i + (size_t)k] = (uint8_t)(dn < 0.0 ? 0.0 : dn > 255.0 ? 255.0 : dn);
        }
    }
    if (c->jpeg_quality > 0)
        sim_jpeg_roundtrip(rgb, rig->width, rig->height, c->jpeg_quality);
}
