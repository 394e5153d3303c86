/* Marching cubes over the fusion grid: closed, consistently oriented surfaces with the right
 * topology, over fields that exercise (nearly) every cube case, ambiguous ones included. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fusion.h"

static struct fusion_volume vol; /* the volume under test */
#include "fusion_grid.h"
#include "test_util.h"
#include "mc_table.h"
#include "storage_posix.h"

struct collected {
    float *pos;
    uint32_t *tri;
    uint32_t nv, nt, cap_v, cap_t;
};

static int on_vertex(void *priv, const struct mesh_vertex *v)
{
    const float *p = v->pos;
    struct collected *c = priv;
    if (c->nv == c->cap_v) {
        c->cap_v = c->cap_v ? 2 * c->cap_v : 4096;
        c->pos = realloc(c->pos, sizeof(float) * 3 * c->cap_v);
    }
    memcpy(&c->pos[3 * c->nv++], p, 3 * sizeof(float));
    return 0;
}

static int on_triangle(void *priv, uint32_t a, uint32_t b, uint32_t t)
{
    struct collected *c = priv;
    if (c->nt == c->cap_t) {
        c->cap_t = c->cap_t ? 2 * c->cap_t : 4096;
        c->tri = realloc(c->tri, sizeof(uint32_t) * 3 * c->cap_t);
    }
    c->tri[3 * c->nt] = a;
    c->tri[3 * c->nt + 1] = b;
    c->tri[3 * c->nt + 2] = t;
    c->nt++;
    return 0;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Every directed edge once and its reverse once: closed and consistently oriented.
 * Returns the Euler characteristic V - E + F. */
static long check_closed(const struct collected *c)
{
    uint64_t *dir = malloc(sizeof(uint64_t) * 3 * c->nt);
    for (uint32_t t = 0; t < c->nt; t++)
        for (int k = 0; k < 3; k++) {
            uint64_t a = c->tri[3 * t + k], b = c->tri[3 * t + (k + 1) % 3];
            assert_true(a != b && a < c->nv && b < c->nv);
            dir[3 * t + k] = a << 32 | b;
        }
    qsort(dir, 3 * (size_t)c->nt, sizeof(uint64_t), cmp_u64);
    for (size_t i = 0; i < 3 * (size_t)c->nt; i++) {
        if (i > 0 && dir[i] == dir[i - 1])
            fail_msg("directed edge %llu used twice: orientation flips",
                     (unsigned long long)dir[i]);
        uint64_t rev = (dir[i] & 0xFFFFFFFFu) << 32 | dir[i] >> 32;
        if (bsearch(&rev, dir, 3 * (size_t)c->nt, sizeof(uint64_t), cmp_u64) == NULL)
            fail_msg("edge without its twin: the surface has a hole");
    }
    free(dir);
    return (long)c->nv - (long)(3 * (size_t)c->nt / 2) + (long)c->nt;
}

static struct fusion_params grid_params(void)
{
    struct fusion_params p = {.voxel_mm = 1.0,
                              .radius_mm = 30,
                              .bottom_mm = 0,
                              .top_mm = 60,
                              .truncation_mm = 3.0,
                              .max_weight = 50,
                              .edge_fade_px = 10};
    return p;
}

static double sphere(vec3 p, void *ctx)
{
    (void)ctx;
    return v3_len(v3_sub(p, v3(0.3, -0.2, 30.1))) - 20.0;
}

static double torus(vec3 p, void *ctx)
{
    (void)ctx;
    vec3 q = v3_sub(p, v3(0, 0, 30));
    double ring = sqrt(q.x * q.x + q.y * q.y) - 18.0;
    return sqrt(ring * ring + q.z * q.z) - 6.0;
}

/* Smooth random blobs, with a shell that keeps the surface inside the grid: many cube cases. */
static double blobs(vec3 p, void *ctx)
{
    const double *c = ctx;
    double d = 0.0;
    for (int k = 0; k < 40; k++) {
        vec3 q = v3_sub(p, v3(c[4 * k], c[4 * k + 1], c[4 * k + 2]));
        d += c[4 * k + 3] * exp(-v3_dot(q, q) / 6.0);
    }
    double r = v3_len(v3_sub(p, v3(0, 0, 30)));
    return r > 24.0 ? r - 24.0 + 1.0 : 0.4 - d;
}

static void extract(double (*fn)(vec3, void *), void *ctx, struct collected *c)
{
    struct fusion_params p = grid_params();
    assert_int_equal(fusion_begin(&vol, &p), 0);
    assert_int_equal(fusion_fill(&vol, fn, ctx), 0);
    memset(c, 0, sizeof(*c));
    struct mesh_sink sink = {on_vertex, on_triangle, c};
    assert_int_equal(fusion_extract(&vol, &sink), 0);
}

static void test_sphere_is_closed_genus_0(void **state)
{
    (void)state;
    struct collected c;
    extract(sphere, NULL, &c);
    assert_true(c.nt > 1000);
    assert_int_equal(check_closed(&c), 2);
    /* outward: every triangle faces away from the centre, and vertices lie on the sphere */
    for (uint32_t t = 0; t < c.nt; t++) {
        const float *a = &c.pos[3 * c.tri[3 * t]], *b = &c.pos[3 * c.tri[3 * t + 1]],
                    *d = &c.pos[3 * c.tri[3 * t + 2]];
        vec3 n = v3_cross(v3(b[0] - a[0], b[1] - a[1], b[2] - a[2]),
                          v3(d[0] - a[0], d[1] - a[1], d[2] - a[2]));
        assert_true(v3_dot(n, v3(a[0] - 0.3, a[1] + 0.2, a[2] - 30.1)) > 0.0);
    }
    for (uint32_t v = 0; v < c.nv; v++)
        assert_true(fabs(sphere(v3(c.pos[3 * v], c.pos[3 * v + 1], c.pos[3 * v + 2]), NULL)) <
                    0.05);
    free(c.pos);
    free(c.tri);
}

static void test_torus_is_closed_genus_1(void **state)
{
    (void)state;
    struct collected c;
    extract(torus, NULL, &c);
    assert_int_equal(check_closed(&c), 0);
    free(c.pos);
    free(c.tri);
}

static void test_random_blobs_stay_closed(void **state)
{
    (void)state;
    double centres[40 * 4];
    srand(3);
    for (int k = 0; k < 40; k++) {
        centres[4 * k] = (rand() % 300) / 10.0 - 15.0;
        centres[4 * k + 1] = (rand() % 300) / 10.0 - 15.0;
        centres[4 * k + 2] = 15.0 + (rand() % 300) / 10.0;
        centres[4 * k + 3] = 0.5 + (rand() % 100) / 100.0;
    }
    struct collected c;
    extract(blobs, centres, &c);
    assert_true(c.nt > 1000);
    check_closed(&c); /* any genus, but closed and oriented */
    free(c.pos);
    free(c.tri);
}

/* A sphere and a crumb floating beside it (what a stray reflection leaves in a scan). */
static double sphere_and_crumb(vec3 p, void *ctx)
{
    (void)ctx;
    double crumb = v3_len(v3_sub(p, v3(25.0, 0.0, 52.0))) - 2.5;
    return fmin(sphere(p, NULL), crumb);
}

/* "element NAME N" from a PLY header. */
static long ply_count(const char *path, const char *name)
{
    char line[128], want[64];
    long n = -1;
    snprintf(want, sizeof(want), "element %s %%ld", name);
    FILE *f = fopen(path, "rb");
    while (f != NULL && fgets(line, sizeof(line), f) != NULL && strncmp(line, "end_header", 10))
        if (sscanf(line, want, &n) == 1)
            break;
    if (f != NULL)
        fclose(f);
    return n;
}

/* The crumb is left out of every output; the STL holds the sphere's triangles, outward. */
static void test_fragments_left_out_and_stl(void **state)
{
    (void)state;
    struct collected whole;
    extract(sphere_and_crumb, NULL, &whole);
    struct mesh_summary ms;
    assert_int_equal(fusion_mesh_prepare(&vol, 0.05, &ms), 0);
    assert_int_equal(ms.vertices, whole.nv);
    assert_int_equal(ms.triangles, whole.nt);
    assert_int_equal(ms.pieces, 2);
    assert_int_equal(ms.removed_pieces, 1);
    assert_true(ms.kept_triangles < ms.triangles && ms.kept_triangles > 0.9 * ms.triangles);
    struct hal_storage st;
    storage_posix_init(&st);
    assert_int_equal(system("mkdir -p build/test_fusion"), 0);
    assert_int_equal(fusion_write_ply(&vol, &st, "build/test_fusion/mesh.ply"), 0);
    assert_int_equal(fusion_write_stl(&vol, &st, "build/test_fusion/mesh.stl"), 0);
    assert_int_equal(ply_count("build/test_fusion/mesh.ply", "vertex"), ms.kept_vertices);
    assert_int_equal(ply_count("build/test_fusion/mesh.ply", "face"), ms.kept_triangles);
    FILE *f = fopen("build/test_fusion/mesh.stl", "rb");
    assert_non_null(f);
    char header[80];
    uint32_t count = 0;
    assert_int_equal(fread(header, 1, 80, f), 80);
    assert_true(strncmp(header, "solid", 5) != 0); /* not mistaken for ASCII STL */
    assert_int_equal(fread(&count, 4, 1, f), 1);   /* little-endian host */
    assert_int_equal(count, ms.kept_triangles);
    for (uint32_t t = 0; t < count; t++) {
        float v[12];
        uint16_t attr;
        assert_int_equal(fread(v, sizeof(float), 12, f), 12);
        assert_int_equal(fread(&attr, 2, 1, f), 1);
        vec3 n = v3(v[0], v[1], v[2]), a = v3(v[3], v[4], v[5]);
        assert_true(fabs(v3_len(n) - 1.0) < 1e-4);
        for (int k = 0; k < 3; k++) /* on the sphere, none on the crumb */
            assert_true(fabs(sphere(v3(v[3 + 3 * k], v[4 + 3 * k], v[5 + 3 * k]), NULL)) < 0.05);
        assert_true(v3_dot(n, v3_sub(a, v3(0.3, -0.2, 30.1))) > 0.0);
    }
    assert_int_equal(fgetc(f), EOF);
    fclose(f);
    assert_int_equal(fusion_mesh_prepare(&vol, 0.0, &ms), 0); /* 0: every piece kept */
    assert_int_equal(ms.removed_pieces, 0);
    assert_int_equal(ms.kept_triangles, whole.nt);
    free(whole.pos);
    free(whole.tri);
}

/* The sphere as a scan sees it: observed near its surface only (within the truncation, as
 * the fusion observes), with an unobserved patch 8 mm across on its side; with @p ctx, also
 * nothing below 6 mm (the rig's cameras look down) and standing on the table. */
static double scanned_sphere(vec3 p, void *ctx)
{
    vec3 c = ctx != NULL ? v3(0, 0, 20) : v3(0.3, -0.2, 30.1);
    double d = v3_len(v3_sub(p, c)) - 20.0;
    vec3 patch = v3_add(c, v3(20, 0, 0));
    if (fabs(d) > 2.5 || v3_len(v3_sub(p, patch)) < 4.0 || (ctx != NULL && p.z < 6.0))
        return NAN;
    return d;
}

/* A hole of 8 mm is filled with max_hole_mm = 10: the surface closes. */
static void test_small_hole_filled(void **state)
{
    (void)state;
    struct collected c;
    uint32_t filled;
    extract(scanned_sphere, NULL, &c); /* with the hole: must not be closed */
    struct mesh_summary ms;
    assert_int_equal(fusion_mesh_prepare(&vol, 0.0, &ms), 0);
    free(c.pos);
    free(c.tri);
    assert_int_equal(fusion_fill_holes(&vol, 10.0, &filled), 0);
    assert_true(filled > 0);
    memset(&c, 0, sizeof(c));
    struct mesh_sink sink = {on_vertex, on_triangle, &c};
    assert_int_equal(fusion_extract(&vol, &sink), 0);
    assert_true(c.nt > ms.triangles);
    assert_int_equal(check_closed(&c), 2);
    free(c.pos);
    free(c.tri);
}

/* The same hole closed on the mesh (fusion_mesh_fill_holes, the volume untouched): one boundary
 * loop fanned, the surface closed and consistently oriented (check_closed), a sphere again;
 * a bound under the hole's size leaves it open; before prepare, refused. */
static void test_small_hole_closed_on_the_mesh(void **state)
{
    (void)state;
    struct collected c;
    struct mesh_summary ms, after;
    struct mesh_hole_report rep;
    extract(scanned_sphere, NULL, &c);
    free(c.pos);
    free(c.tri);
    assert_int_equal(fusion_mesh_fill_holes(&vol, 20.0, &rep), -EINVAL); /* not prepared */
    assert_int_equal(fusion_mesh_prepare(&vol, 0.0, &ms), 0);
    assert_int_equal(fusion_mesh_fill_holes(&vol, 5.0, &rep), 0); /* the hole is ~10 mm */
    assert_true(rep.boundary_edges > 8);
    assert_int_equal(rep.filled, 0);
    assert_int_equal(rep.left, 1);
    assert_int_equal(fusion_mesh_fill_holes(&vol, 20.0, &rep), 0);
    uint32_t loop = rep.boundary_edges;
    assert_int_equal(rep.filled, 1);
    assert_int_equal(rep.left, 0);
    assert_int_equal(fusion_mesh_counts(&vol, &after), 0);
    assert_int_equal(after.kept_vertices, ms.kept_vertices + 1);
    assert_int_equal(after.kept_triangles, ms.kept_triangles + loop);
    memset(&c, 0, sizeof(c));
    struct mesh_sink sink = {on_vertex, on_triangle, &c};
    assert_int_equal(fusion_extract_prepared(&vol, &sink), 0);
    assert_int_equal(check_closed(&c), 2);
    free(c.pos);
    free(c.tri);
    assert_int_equal(fusion_mesh_fill_holes(&vol, 20.0, &rep), 0); /* nothing left to close */
    assert_int_equal(rep.boundary_edges, 0);
    assert_int_equal(rep.filled, 0);
}

/* Standing on the table, unseen below 6 mm and inside: closed watertight, solid (one surface,
 * no inner wall), nothing below the table. */
static void test_watertight_closes_at_the_table(void **state)
{
    (void)state;
    struct collected c;
    uint32_t filled, inside;
    int standing = 1;
    struct fusion_params p = grid_params();
    p.bottom_mm = -3;
    assert_int_equal(fusion_begin(&vol, &p), 0);
    assert_int_equal(fusion_fill(&vol, scanned_sphere, &standing), 0);
    assert_int_equal(fusion_fill_holes(&vol, 10.0, &filled), 0);
    assert_int_equal(fusion_close_watertight(&vol, 10.0, 1, &inside), 0);
    /* the core no filling reached (radius 20 - 2.5 observed - 5 filled) is decided solid */
    assert_true(inside > 0.8 * 4.0 / 3.0 * M_PI * 12.5 * 12.5 * 12.5);
    struct mesh_summary ms; /* crumbs the opening leaves beside the surface are fragments */
    assert_int_equal(fusion_mesh_prepare(&vol, 0.01, &ms), 0);
    memset(&c, 0, sizeof(c));
    struct mesh_sink sink = {on_vertex, on_triangle, &c};
    assert_int_equal(fusion_extract_prepared(&vol, &sink), 0);
    assert_int_equal(c.nt, ms.kept_triangles);
    assert_int_equal(check_closed(&c), 2); /* one closed surface: no hollow inside */
    for (uint32_t v = 0; v < c.nv; v++) {
        vec3 q = v3(c.pos[3 * v], c.pos[3 * v + 1], c.pos[3 * v + 2]);
        assert_true(q.z > -0.01);
        int patch = v3_len(v3_sub(q, v3(20, 0, 20))) < 6.0; /* filled flat: off by < 1 mm */
        if (q.z > 12.0) /* above the unseen band and its closure: the sphere itself */
            assert_true(fabs(v3_len(v3_sub(q, v3(0, 0, 20))) - 20.0) < (patch ? 1.0 : 0.3));
    }
    free(c.pos);
    free(c.tri);
}

struct colour_check {
    uint32_t vertices, red, not_coloured;
};

static int check_colour(void *priv, const struct mesh_vertex *v)
{
    struct colour_check *c = priv;
    c->vertices++;
    c->red += v->rgb[0] == 200 * 257 && v->rgb[1] == 30 * 257 && v->rgb[2] == 20 * 257;
    c->not_coloured += !v->coloured;
    return 0;
}

/* A cap no view could colour (every estimate there was none: COLOUR_NO_ESTIMATE) takes the
 * colour of the surface around it, ring by ring; with no colour anywhere, mid grey, counted. */
static void test_uncoloured_surface_takes_its_neighbours_colour(void **state)
{
    (void)state;
    struct fusion_params p = grid_params();
    assert_int_equal(fusion_begin(&vol, &p), 0);
    assert_int_equal(fusion_fill(&vol, sphere, NULL), 0);
    uint32_t dims[3], cap = 0;
    assert_int_equal(fusion_dims(&p, dims), 0);
    for (uint32_t z = 0; z < dims[2]; z++)
        for (uint32_t y = 0; y < dims[1]; y++)
            for (uint32_t x = 0; x < dims[0]; x++) {
                struct voxel *v = &vol.grid[vidx(&vol, x, y, z)];
                static const uint8_t red[3] = {200, 30, 20};
                memcpy(v->rgb, red, 3);
                if (vol.origin.z + z * p.voxel_mm > 42.0) { /* the top 8 mm */
                    memset(v->rgb, 0, 3);
                    v->colour_weight = 0;
                    cap++;
                }
            }
    struct mesh_summary ms;
    assert_int_equal(fusion_mesh_prepare(&vol, 0.0, &ms), 0);
    assert_true(cap > 0 && ms.colour_filled > 100);
    assert_int_equal(ms.uncoloured, 0);
    struct colour_check c = {0, 0, 0};
    struct mesh_sink sink = {check_colour, NULL, &c};
    assert_int_equal(fusion_extract_prepared(&vol, &sink), 0);
    assert_int_equal(c.vertices, ms.kept_vertices);
    assert_int_equal(c.red, c.vertices); /* no black, no raw: the surface's own red */
    assert_int_equal(c.not_coloured, 0);
    /* nothing coloured at all: every vertex marked grey */
    for (size_t i = 0; i < (size_t)dims[0] * dims[1] * dims[2]; i++)
        vol.grid[i].colour_weight = 0;
    assert_int_equal(fusion_mesh_prepare(&vol, 0.0, &ms), 0);
    assert_int_equal(ms.colour_filled, 0);
    assert_int_equal(ms.uncoloured, ms.kept_vertices);
}

/* The generated table: complementary cases mirror each other, and every case's triangles are
 * edges of the cube where the sign changes. */
static void test_table_properties(void **state)
{
    (void)state;
    mc_table_build();
    assert_int_equal(mc_table_case(0)->tri_count, 0);
    assert_int_equal(mc_table_case(255)->tri_count, 0);
    assert_int_equal(mc_table_case(1)->tri_count, 1);
    for (unsigned m = 1; m < 255; m++) {
        const struct mc_case *c = mc_table_case(m);
        assert_true(c->tri_count >= 1);
        for (unsigned t = 0; t < c->tri_count; t++)
            for (int k = 0; k < 3; k++) {
                int e = c->edge[t][k];
                unsigned a = mc_edge_corner[e][0], b = mc_edge_corner[e][1];
                assert_int_not_equal((m >> a) & 1u, (m >> b) & 1u);
            }
    }
}

/* Two volumes (struct fusion_volume) are two models: a torus fused and meshed in a second one
 * between the sphere's preparation and its writing leaves the sphere's mesh.ply byte for byte
 * what it was written as before. */
/* fit_volume: points over the table beyond the volume grow it to hold them (the radius by whole
 * voxels), with the band and two voxels to spare; a few stray ones, points off the table, a
 * volume beyond the compiled limits or fit_volume = 0 leave it as it is. */
static void test_volume_fitted_to_what_was_seen(void **state)
{
    (void)state;
    struct fusion_params p = grid_params(), f; /* radius 30, top 60, voxel 1, band 3 */
    p.voxel_mm = 0.7;
    p.fit_volume = 1;
    struct fusion_outside seen = {0};
    for (int i = 0; i < 5000; i++) /* inside: nothing grows */
        fusion_outside_add(&seen, &p, v3(10.0 * sin(i), 10.0 * cos(i), 1.0 + i % 55));
    assert_int_equal(fusion_fit(&p, &seen, &f), 0);
    assert_memory_equal(&f, &p, sizeof(p));
    for (int i = 0; i < 7; i++) /* 7 stray points far above and beside: still nothing */
        fusion_outside_add(&seen, &p, v3(40.0, 0.0, 90.0));
    for (int i = 0; i < 50; i++) /* under the table's clearance, or far off it: not the object */
        fusion_outside_add(&seen, &p, v3(50.0, 0.0, 2.0)),
            fusion_outside_add(&seen, &p, v3(70, 0, 30));
    assert_int_equal(fusion_fit(&p, &seen, &f), 0);
    for (int i = 0; i < 10; i++) /* now 17 above (90 mm), 17 beside (40 mm): grown */
        fusion_outside_add(&seen, &p, v3(0.0, -40.0, 90.0));
    assert_int_equal(seen.above, 17);
    assert_int_equal(seen.beside, 17);
    assert_int_equal(fusion_fit(&p, &seen, &f), 1);
    assert_true(fabs(f.top_mm - (90.0 + 3.0 + 1.4)) < 1e-9);
    double voxels = (f.radius_mm - p.radius_mm) / p.voxel_mm; /* whole voxels, enough */
    assert_true(fabs(voxels - round(voxels)) < 1e-9 && f.radius_mm >= 40.0 + 3.0 + 1.4 &&
                f.radius_mm < 40.0 + 3.0 + 1.4 + p.voxel_mm);
    assert_true(f.bottom_mm == p.bottom_mm && f.voxel_mm == p.voxel_mm);
    /* a thousandth of what was fused at least: 17 of 50,000 are strays */
    for (int i = 0; i < 45000; i++)
        fusion_outside_add(&seen, &p, v3(0.0, 0.0, 30.0));
    assert_int_equal(fusion_fit(&p, &seen, &f), 0);
    seen.fused = 1000;
    p.fit_volume = 0;
    assert_int_equal(fusion_fit(&p, &seen, &f), 0);
    assert_memory_equal(&f, &p, sizeof(p));
    p.fit_volume = 1; /* 1,000 m tall: beyond any grid this build has */
    seen.top_seen_mm = 1e6;
    assert_int_equal(fusion_fit(&p, &seen, &f), -E2BIG);
    assert_memory_equal(&f, &p, sizeof(p));
}

/* An object placed far off the axis (a bunny 150 mm from it, on the table's rim): the square
 * about the axis that would hold it is beyond the compiled limits, one moved towards it (by
 * whole voxels) holds it and the configured volume both; points on both sides that far are
 * beyond any square this build has. */
static void test_volume_moved_to_an_object_off_the_axis(void **state)
{
    (void)state;
    struct fusion_params p = grid_params(), f;
    p.fit_volume = 1;
    p.voxel_mm = 1.0;
    p.radius_mm = 0.35 * FUSION_MAX_DIM; /* 140 mm: points within 280 mm count as the object */
    const double far_x = 0.6 * FUSION_MAX_DIM, spare = 3.0 + 2.0;
    struct fusion_outside seen = {0};
    for (int i = 0; i < 2000; i++) /* the object, from inside the square to far_x beyond it */
        fusion_outside_add(&seen, &p,
                           v3(p.radius_mm - 20.0 + (far_x - p.radius_mm + 20.0) * i / 1999.0,
                              10.0 * sin(i), 20.0));
    assert_true(seen.beside > 100);
    struct fusion_params about_axis = p;
    about_axis.radius_mm = far_x + spare; /* what the square about the axis would need */
    uint32_t dims[3];
    assert_int_equal(fusion_dims(&about_axis, dims), -E2BIG);
    assert_int_equal(fusion_fit(&p, &seen, &f), 1);
    assert_int_equal(fusion_dims(&f, dims), 0);
    /* it holds the configured square and the object, with the room asked for */
    assert_true(f.centre_mm[0] - f.radius_mm <= -p.radius_mm + 1e-9);
    assert_true(f.centre_mm[0] + f.radius_mm >= far_x + spare - 1e-9);
    assert_true(f.centre_mm[1] - f.radius_mm <= -p.radius_mm + 1e-9 &&
                f.centre_mm[1] + f.radius_mm >= p.radius_mm - 1e-9);
    assert_true(f.centre_mm[0] > 0.0 && f.centre_mm[1] == 0.0);
    /* the grid's voxels stay where they were: its corner moved by whole voxels */
    for (int a = 0; a < 2; a++) {
        double moved = (f.centre_mm[a] - f.radius_mm + p.radius_mm) / p.voxel_mm;
        assert_true(fabs(moved - round(moved)) < 1e-9);
    }
    assert_true(f.top_mm == p.top_mm && f.voxel_mm == p.voxel_mm);
    /* as far on the other side too: no square this build has holds both */
    for (int i = 0; i < 2000; i++)
        fusion_outside_add(&seen, &p, v3(-far_x, 10.0 * sin(i), 20.0));
    assert_int_equal(fusion_fit(&p, &seen, &f), -E2BIG);
    assert_memory_equal(&f, &p, sizeof(p));
}

static void test_two_volumes_are_independent(void **state)
{
    (void)state;
    static struct fusion_volume other;
    struct fusion_params p = grid_params();
    struct hal_storage st;
    storage_posix_init(&st);
    assert_int_equal(system("mkdir -p build/test_fusion"), 0);
    struct mesh_summary sphere_ms, torus_ms;
    assert_int_equal(fusion_begin(&vol, &p), 0);
    assert_int_equal(fusion_fill(&vol, sphere, NULL), 0);
    assert_int_equal(fusion_mesh_prepare(&vol, 0.0, &sphere_ms), 0);
    assert_int_equal(fusion_write_ply(&vol, &st, "build/test_fusion/alone.ply"), 0);
    assert_int_equal(fusion_begin(&other, &p), 0);
    assert_int_equal(fusion_fill(&other, torus, NULL), 0);
    assert_int_equal(fusion_mesh_prepare(&other, 0.0, &torus_ms), 0);
    assert_int_equal(fusion_write_ply(&other, &st, "build/test_fusion/torus.ply"), 0);
    assert_int_equal(fusion_write_ply(&vol, &st, "build/test_fusion/beside.ply"), 0);
    assert_true(sphere_ms.kept_vertices != torus_ms.kept_vertices);
    assert_false(test_files_equal("build/test_fusion/alone.ply", "build/test_fusion/torus.ply"));
    assert_true(test_files_equal("build/test_fusion/alone.ply", "build/test_fusion/beside.ply"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table_properties),
        cmocka_unit_test(test_sphere_is_closed_genus_0),
        cmocka_unit_test(test_torus_is_closed_genus_1),
        cmocka_unit_test(test_random_blobs_stay_closed),
        cmocka_unit_test(test_fragments_left_out_and_stl),
        cmocka_unit_test(test_small_hole_filled),
        cmocka_unit_test(test_small_hole_closed_on_the_mesh),
        cmocka_unit_test(test_uncoloured_surface_takes_its_neighbours_colour),
        cmocka_unit_test(test_watertight_closes_at_the_table),
        cmocka_unit_test(test_volume_fitted_to_what_was_seen),
        cmocka_unit_test(test_volume_moved_to_an_object_off_the_axis),
        cmocka_unit_test(test_two_volumes_are_independent),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
