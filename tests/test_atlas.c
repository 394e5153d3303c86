/* The views' colour on the mesh and its texture atlas: charts that cover the mesh without
 * overlapping, texture coordinates inside their chart, and a view's colour landing where the view
 * saw it, in the texture and on the vertices, with a texture or without (a sphere painted by
 * octant, seen by a pinhole camera; what no view saw takes the vertex colours, which keep the
 * fusion grid's there). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "atlas.h"
#include "srgb.h"

static struct fusion_volume vol;
static struct atlas atlas;

#define W 640u
#define H 480u
static uint8_t reason[W * H], rgb[W * H * 3];
static float xyz[W * H * 3], normal[W * H * 3], confidence[W * H];

static const vec3 centre = {0.3, -0.2, 30.1};
#define RADIUS 20.0

static double sphere(vec3 p, void *ctx)
{
    (void)ctx;
    return v3_len(v3_sub(p, centre)) - RADIUS;
}

/* The paint: a colour per half-space of x and of z about the centre (object frame). */
static void paint(vec3 p_obj, uint8_t out[3])
{
    out[0] = p_obj.x > centre.x ? 200 : 20;
    out[1] = p_obj.z > centre.z ? 180 : 30;
    out[2] = 60;
}

/* Distance from the paint's boundaries. */
static double from_boundary(vec3 p_obj)
{
    return fmin(fabs(p_obj.x - centre.x), fabs(p_obj.z - centre.z));
}

static void prepare_sphere(void)
{
    struct fusion_params p = {.voxel_mm = 1.0,
                              .radius_mm = 30,
                              .bottom_mm = 0,
                              .top_mm = 60,
                              .truncation_mm = 3.0,
                              .max_weight = 50,
                              .edge_fade_px = 10};
    struct mesh_summary ms;
    assert_int_equal(fusion_begin(&vol, &p), 0);
    assert_int_equal(fusion_fill(&vol, sphere, NULL), 0);
    assert_int_equal(fusion_mesh_prepare(&vol, 0.0, &ms), 0);
    assert_true(ms.kept_triangles > 1000);
}

/* The atlas in the spent grid's memory, as the job makes it. */
static int build(double texel_mm, struct atlas_report *rep)
{
    size_t bytes;
    void *work = fusion_spend_grid(&vol, &bytes);
    return atlas_build(&atlas, &vol, texel_mm, work, bytes, rep);
}

static void test_charts_cover_the_mesh_without_overlap(void **state)
{
    (void)state;
    struct atlas_report rep;
    prepare_sphere();
    assert_int_equal(build(0.25, &rep), 0);
    assert_true(rep.charts >= 6); /* a sphere faces every axis direction */
    assert_true(rep.width > 0 && rep.width <= ATLAS_MAX_SIDE && rep.height <= ATLAS_MAX_SIDE);
    assert_true(rep.used_share > 0.3 && rep.used_share <= 1.0);
    assert_true(fabs(rep.texel_mm - 0.25) < 1e-12); /* it fits at the texel asked */
    for (uint32_t a = 0; a < rep.charts; a++) {
        const struct atlas_chart *ca = &atlas.chart[a];
        assert_true(ca->x0 + ca->w <= rep.width && ca->y0 + ca->h <= rep.height);
        for (uint32_t b = a + 1; b < rep.charts; b++) {
            const struct atlas_chart *cb = &atlas.chart[b];
            int apart = ca->x0 + ca->w <= cb->x0 || cb->x0 + cb->w <= ca->x0 ||
                        ca->y0 + ca->h <= cb->y0 || cb->y0 + cb->h <= ca->y0;
            assert_true(apart);
        }
    }
    /* every kept triangle's corners inside its chart, inside the gutter */
    uint32_t placed = 0;
    for (uint32_t t = 0; t < vol.mp.s.triangles; t++) {
        float uv[2];
        const struct atlas_chart *ch = &atlas.chart[atlas.tri_chart[t]];
        for (int k = 0; k < 3; k++) {
            assert_int_equal(atlas_uv(&atlas, &vol, t, k, uv), 0);
            double x = uv[0] * rep.width, y = uv[1] * rep.height;
            assert_true(x >= ch->x0 + ATLAS_GUTTER - 1e-3 && x <= ch->x0 + ch->w - ATLAS_GUTTER);
            assert_true(y >= ch->y0 + ATLAS_GUTTER - 1e-3 && y <= ch->y0 + ch->h - ATLAS_GUTTER);
        }
        placed++;
    }
    assert_int_equal(placed, vol.mp.s.kept_triangles);
    assert_int_equal(atlas_uv(&atlas, &vol, vol.mp.s.triangles, 0, (float[2]){0}), -EINVAL);
}

/* A camera 300 mm from the sphere along the object's -y, looking at it: its range image
 * (ray-sphere intersections), normals and the paint. */
static void render_view(const struct scan_calib *c, const struct frame_xform *obj_from_cam)
{
    memset(reason, SCAN_VALID + 1, sizeof(reason)); /* any reason but valid */
    vec3 o = frame_point_inv(obj_from_cam, centre); /* the centre in the camera frame */
    for (uint32_t y = 0; y < H; y++)
        for (uint32_t x = 0; x < W; x++) {
            size_t i = (size_t)y * W + x;
            vec3 d = v3_norm(
                v3((x - c->cam_cx_px) / c->cam_fx_px, (y - c->cam_cy_px) / c->cam_fy_px, 1));
            double b = v3_dot(d, o), disc = b * b - v3_dot(o, o) + RADIUS * RADIUS;
            if (disc <= 0.0)
                continue;
            vec3 p = v3_scale(d, b - sqrt(disc)), n = v3_norm(v3_sub(p, o));
            memcpy(&xyz[3 * i], (float[3]){(float)p.x, (float)p.y, (float)p.z}, sizeof(float[3]));
            memcpy(&normal[3 * i], (float[3]){(float)n.x, (float)n.y, (float)n.z},
                   sizeof(float[3]));
            paint(frame_point(obj_from_cam, p), &rgb[3 * i]);
            confidence[i] = 1.0f;
            reason[i] = SCAN_VALID;
        }
}

/* The view of test_a_view_colours_what_it_saw, added to the atlas built. */
static void add_the_view(void)
{
    struct scan_calib c = {.cam_fx_px = 800,
                           .cam_fy_px = 800,
                           .cam_cx_px = 319.5,
                           .cam_cy_px = 239.5,
                           .cam_width = W,
                           .cam_height = H};
    /* camera frame: x right, y down, z forward; object frame: x right, y away (forward), z up.
     * p_obj = rot (p_cam - origin): the camera (p_cam = 0) at object (0.3, -320, 30.1) */
    struct frame_xform obj_from_cam = {{1, 0, 0, 0, 0, 1, 0, -1, 0}, {0, 0, 0}};
    obj_from_cam.origin = v3_scale(frame_dir_inv(&obj_from_cam, v3(0.3, -320.0, 30.1)), -1.0);
    vec3 camera = frame_point(&obj_from_cam, v3(0, 0, 0));
    assert_true(fabs(camera.y + 320.0) < 1e-9 && fabs(camera.z - 30.1) < 1e-9);
    render_view(&c, &obj_from_cam);
    struct decode_maps m = {.reason = reason, .width = W, .height = H};
    struct tri_range r = {.xyz_mm = xyz, .normal = normal, .width = W, .height = H};
    assert_int_equal(atlas_add_view(&atlas, &vol, NULL, &c, &obj_from_cam, &m, &r, rgb, confidence),
                     0);
}

/* Each vertex facing the camera away from the paint's edges has the paint's colour (16 bits,
 * from the view's linear bytes); the far side keeps the grid's grey (fusion_fill: 128). */
static void check_vertices(uint32_t coloured)
{
    uint32_t seen = 0, right = 0, back = 0, grey = 0;
    for (uint32_t v = 0; v < vol.mp.s.vertices; v++) {
        const float *q = &vol.mesh_pos[3 * (size_t)v];
        const uint16_t *got = &vol.mesh_rgb[3 * (size_t)v];
        vec3 p = v3(q[0], q[1], q[2]), from_centre = v3_sub(p, centre);
        if (from_centre.y < -0.5 * RADIUS && from_boundary(p) > 2.0) {
            uint8_t want[3];
            paint(p, want);
            int ok = 1;
            for (int k = 0; k < 3; k++)
                ok &= abs((int)got[k] - 257 * (int)want[k]) <= 257;
            seen++;
            right += (uint32_t)ok;
        } else if (from_centre.y > 0.5 * RADIUS) {
            back++;
            grey += got[0] == 128 * 257 && got[1] == 128 * 257 && got[2] == 128 * 257;
        }
    }
    assert_true(seen > 100);
    assert_int_equal(right, seen);
    assert_true(back > 100);
    assert_int_equal(grey, back);
    assert_true(coloured >= seen && coloured < vol.mp.s.vertices - back);
}

/* The sphere's atlas at @p texel_mm (0: no texture) coloured by the view, its vertices checked.
 * @retval the texels no view coloured */
static uint32_t colour_from_the_view(double texel_mm, struct atlas_report *rep)
{
    uint32_t uncoloured, vertices;
    prepare_sphere();
    assert_int_equal(build(texel_mm, rep), 0);
    add_the_view();
    assert_int_equal(atlas_finish(&atlas, &vol, &uncoloured, &vertices), 0);
    check_vertices(vertices);
    return uncoloured;
}

static void test_a_view_colours_what_it_saw(void **state)
{
    (void)state;
    struct atlas_report rep;
    assert_true(colour_from_the_view(0.25, &rep) > 0); /* the far side: no view */
    uint32_t seen = 0, right = 0, back = 0, grey = 0;
    for (uint32_t t = 0; t < vol.mp.s.triangles; t++) {
        const uint32_t *tri = &vol.mesh_tri[3 * (size_t)t];
        vec3 p = v3(0, 0, 0);
        float uvs[3][2];
        for (int k = 0; k < 3; k++) {
            const float *q = &vol.mesh_pos[3 * (size_t)tri[k]];
            p = v3_add(p, v3_scale(v3(q[0], q[1], q[2]), 1.0 / 3.0));
            assert_int_equal(atlas_uv(&atlas, &vol, t, k, uvs[k]), 0);
        }
        /* the texel under the triangle's centroid */
        double u = (uvs[0][0] + uvs[1][0] + uvs[2][0]) / 3.0;
        double v = (uvs[0][1] + uvs[1][1] + uvs[2][1]) / 3.0;
        size_t texel = (size_t)floor(v * rep.height) * rep.width + (size_t)floor(u * rep.width);
        const uint8_t *got = &atlas.texture[3 * texel];
        vec3 from_centre = v3_sub(p, centre);
        if (from_centre.y < -0.5 * RADIUS && from_boundary(p) > 2.0) { /* facing the camera */
            uint8_t want[3];
            paint(p, want);
            int ok = 1;
            for (int k = 0; k < 3; k++)
                ok &= abs((int)got[k] - (int)srgb_encode(want[k])) <= 6;
            seen++;
            right += (uint32_t)ok;
        } else if (from_centre.y > 0.5 * RADIUS) { /* the far side: the vertex colours (grey) */
            back++;
            grey += abs((int)got[0] - (int)got[1]) <= 2 && abs((int)got[1] - (int)got[2]) <= 2;
        }
    }
    assert_true(seen > 500);
    assert_true(right >= 0.98 * seen);
    assert_true(back > 500);
    assert_int_equal(grey, back);
}

/* No texture ([output] texture = 0, texel 0): the vertices take the view's colour all the same,
 * and there is no texture to place a corner in. */
static void test_vertices_coloured_without_a_texture(void **state)
{
    (void)state;
    struct atlas_report rep;
    assert_int_equal(colour_from_the_view(0.0, &rep), 0);
    assert_true(rep.width == 0 && rep.height == 0 && rep.charts == 0);
    float uv[2];
    assert_int_equal(atlas_uv(&atlas, &vol, 0, 0, uv), -EINVAL);
    assert_int_equal(atlas_vertex_uv(&atlas, &vol, 0, uv), -EINVAL);
}

static void test_unprepared_or_no_texel_refused(void **state)
{
    (void)state;
    struct atlas_report rep;
    uint32_t n, nv;
    static uint64_t work[1u << 16]; /* 512 KB */
    memset(&vol.mp, 0, sizeof(vol.mp));
    size_t bytes;
    assert_null(fusion_spend_grid(&vol, &bytes)); /* no mesh made: the grid is the model's */
    assert_int_equal(atlas_build(&atlas, &vol, 0.25, work, sizeof(work), &rep), -EINVAL);
    assert_int_equal(atlas_finish(&atlas, &vol, &n, &nv), -EINVAL);
    prepare_sphere();
    assert_int_equal(atlas_build(&atlas, &vol, -0.25, work, sizeof(work), &rep), -EINVAL);
    assert_int_equal(atlas_build(&atlas, &vol, NAN, work, sizeof(work), &rep), -EINVAL);
    assert_int_equal(atlas_build(&atlas, &vol, 0.0, work, sizeof(work), &rep), -ENOSPC);
    assert_int_equal(atlas_build(&atlas, &vol, 0.25, NULL, sizeof(work), &rep), -EINVAL);
    assert_int_equal(atlas_build(&atlas, &vol, 0.25, (char *)work + 4, 1000, &rep), -EINVAL);
    /* a work space too small for the charts' own bookkeeping */
    assert_int_equal(atlas_build(&atlas, &vol, 0.25, work, sizeof(work), &rep), -ENOSPC);
}

static void test_too_fine_a_texel_grows_until_it_fits(void **state)
{
    (void)state;
    struct atlas_report rep;
    prepare_sphere();
    /* 5000 mm^2 of sphere at 0.001 mm would be 5e9 texels */
    assert_int_equal(build(0.001, &rep), 0);
    assert_true(rep.texel_mm > 0.001);
    assert_true((uint64_t)rep.width * rep.height <= ATLAS_MAX_TEXELS);
    /* the grid is lent out: marching cubes refuses to read it */
    struct mesh_sink none = {NULL, NULL, NULL};
    assert_int_equal(fusion_extract(&vol, &none), -EINVAL);
    assert_true(rep.width <= ATLAS_MAX_SIDE && rep.height <= ATLAS_MAX_SIDE);
    /* and not far from the finest that fits: one step finer would not */
    assert_true(4.0 * M_PI * RADIUS * RADIUS / (rep.texel_mm * rep.texel_mm / 1.5625) >
                0.5 * ATLAS_MAX_TEXELS);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_charts_cover_the_mesh_without_overlap),
        cmocka_unit_test(test_a_view_colours_what_it_saw),
        cmocka_unit_test(test_vertices_coloured_without_a_texture),
        cmocka_unit_test(test_unprepared_or_no_texel_refused),
        cmocka_unit_test(test_too_fine_a_texel_grows_until_it_fits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
