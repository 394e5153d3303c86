/* Tessellated analytic shapes and a small PLY reader for the simulated object. */
#define _POSIX_C_SOURCE 200809L
#include "sim_mesh.h"

#include "vec3.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int mesh_alloc(struct sim_mesh *m, uint32_t verts, uint32_t tris)
{
    memset(m, 0, sizeof(*m));
    m->pos = calloc((size_t)verts * 3, sizeof(float));
    m->normal = calloc((size_t)verts * 3, sizeof(float));
    m->tri = calloc((size_t)tris * 3, sizeof(uint32_t));
    if (m->pos == NULL || m->normal == NULL || m->tri == NULL) {
        sim_mesh_free(m);
        return -ENOMEM;
    }
    return 0;
}

void sim_mesh_free(struct sim_mesh *m)
{
    free(m->pos);
    free(m->normal);
    free(m->tri);
    free(m->rgb);
    free(m->lin);
    free(m->quality);
    memset(m, 0, sizeof(*m));
}

void sim_mesh_linear(const struct sim_mesh *m, uint32_t i, double out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = m->lin != NULL ? m->lin[3 * (size_t)i + (size_t)k]
                                : m->rgb[3 * (size_t)i + (size_t)k] / 255.0;
}

static void set_vert(struct sim_mesh *m, uint32_t i, vec3 p)
{
    m->pos[3 * i] = (float)p.x;
    m->pos[3 * i + 1] = (float)p.y;
    m->pos[3 * i + 2] = (float)p.z;
}

static uint32_t add_tri(struct sim_mesh *m, uint32_t t, uint32_t a, uint32_t b, uint32_t c)
{
    m->tri[3 * t] = a;
    m->tri[3 * t + 1] = b;
    m->tri[3 * t + 2] = c;
    return t + 1;
}

/* A (u, v) grid of vertices from @p f, closed in u when @p wrap_u; two triangles per cell.
 * Every shape below is one or more such grids, so one function serves them all. */
typedef vec3 (*grid_fn)(double u, double v, const double *shape);
static void add_grid(struct sim_mesh *m, uint32_t *vert, uint32_t *tri, uint32_t nu, uint32_t nv,
                     grid_fn f, const double *shape)
{
    uint32_t base = *vert;
    for (uint32_t j = 0; j <= nv; j++)
        for (uint32_t i = 0; i <= nu; i++)
            set_vert(m, base + j * (nu + 1) + i, f((double)i / nu, (double)j / nv, shape));
    for (uint32_t j = 0; j < nv; j++) {
        for (uint32_t i = 0; i < nu; i++) {
            uint32_t a = base + j * (nu + 1) + i, b = a + 1, c = a + nu + 1, d = c + 1;
            *tri = add_tri(m, *tri, a, b, d);
            *tri = add_tri(m, *tri, a, d, c);
        }
    }
    *vert = base + (nu + 1) * (nv + 1);
}

static uint32_t grid_verts(uint32_t nu, uint32_t nv)
{
    return (nu + 1) * (nv + 1);
}

/* A mesh that is one closed grid (sphere, torus). */
static int single_grid_mesh(struct sim_mesh *m, uint32_t nu, uint32_t nv, grid_fn f,
                            const double *shape)
{
    int rc = mesh_alloc(m, grid_verts(nu, nv), 2 * nu * nv);
    if (rc != 0)
        return rc;
    uint32_t vert = 0, tri = 0;
    add_grid(m, &vert, &tri, nu, nv, f, shape);
    m->vert_count = vert;
    m->tri_count = tri;
    sim_mesh_compute_normals(m);
    return 0;
}

static vec3 sphere_fn(double u, double v, const double *s)
{
    double phi = 2.0 * M_PI * u, th = M_PI * (1.0 - v); /* v = 0 at the bottom pole */
    return v3(s[0] * sin(th) * cos(phi), s[0] * sin(th) * sin(phi), s[0] * cos(th));
}

int sim_mesh_sphere(struct sim_mesh *m, double r, uint32_t seg)
{
    double shape[1] = {r};
    return single_grid_mesh(m, seg, seg / 2, sphere_fn, shape);
}

#define CAN_BODY_V 0.6 /* share of the can's side grid rows on its body */

static vec3 cyl_side_fn(double u, double v, const double *s)
{
    double phi = 2.0 * M_PI * u;
    return v3(s[0] * cos(phi), s[0] * sin(phi), s[1] * v);
}
/* Caps as grids from the rim (v = 0) to the centre (v = 1); s[2] = 1 for the top. */
static vec3 cyl_cap_fn(double u, double v, const double *s)
{
    double phi = 2.0 * M_PI * (s[2] > 0.5 ? u : 1.0 - u);
    return v3(s[0] * (1.0 - v) * cos(phi), s[0] * (1.0 - v) * sin(phi), s[2] > 0.5 ? s[1] : 0.0);
}

/* A solid of revolution: its side (@p side_fn of {r, h}, @p nv rows) closed by flat caps of
 * radius @p top_r at h and r at 0. */
static int capped_solid(struct sim_mesh *m, grid_fn side_fn, double r, double top_r, double h,
                        uint32_t seg, uint32_t nv)
{
    uint32_t nu = seg, nc = seg / 8 + 1;
    int rc = mesh_alloc(m, grid_verts(nu, nv) + 2 * grid_verts(nu, nc), 2 * nu * (nv + 2 * nc));
    if (rc != 0)
        return rc;
    uint32_t vert = 0, tri = 0;
    double side[2] = {r, h}, top[3] = {top_r, h, 1.0}, bottom[3] = {r, h, 0.0};
    add_grid(m, &vert, &tri, nu, nv, side_fn, side);
    add_grid(m, &vert, &tri, nu, nc, cyl_cap_fn, top);
    add_grid(m, &vert, &tri, nu, nc, cyl_cap_fn, bottom);
    m->vert_count = vert;
    m->tri_count = tri;
    sim_mesh_compute_normals(m);
    return 0;
}

int sim_mesh_cylinder(struct sim_mesh *m, double r, double h, uint32_t seg)
{
    return capped_solid(m, cyl_side_fn, r, r, h, seg, seg / 4);
}

/* A spray can's side, body then shoulder, s = {r, h}: the body rises to 0.775 h; the shoulder, a
 * quarter ellipse, narrows it to a 0.25 r neck at h (vertical where it meets the body, so the
 * normals run on smoothly). Unlike a plain cylinder's side, the shoulder faces up towards
 * the camera and the lights, so it shows their highlights. */
static vec3 can_side_fn(double u, double v, const double *s)
{
    double phi = 2.0 * M_PI * u, r = s[0], h = s[1], body = 0.775 * h;
    if (v <= CAN_BODY_V)
        return v3(r * cos(phi), r * sin(phi), body * v / CAN_BODY_V);
    double t = 0.5 * M_PI * (v - CAN_BODY_V) / (1.0 - CAN_BODY_V);
    double rad = r * (0.25 + 0.75 * cos(t));
    return v3(rad * cos(phi), rad * sin(phi), body + (h - body) * sin(t));
}

int sim_mesh_can(struct sim_mesh *m, double r, double h, uint32_t seg)
{
    return capped_solid(m, can_side_fn, r, 0.25 * r, h, seg, seg / 2);
}

/* One face of the box: s = {sx, sy, sz, axis, sign}; separate vertices keep the edges sharp. */
static vec3 box_face_fn(double u, double v, const double *s)
{
    int axis = (int)s[3];
    double sign = s[4];
    double a = (u - 0.5), b = (v - 0.5);
    vec3 p;
    if (axis == 0)
        p = v3(0.5 * sign, a * sign, b);
    else if (axis == 1)
        p = v3(-a * sign, 0.5 * sign, b);
    else
        p = v3(a * sign, b, 0.5 * sign);
    return v3(p.x * s[0], p.y * s[1], (p.z + 0.5) * s[2]);
}

/* Wind every triangle so that its normal points away from @p point (@p sign 1) or towards it
 * (-1): grids of different faces do not wind alike. */
static void orient_faces(struct sim_mesh *m, vec3 point, double sign)
{
    for (uint32_t t = 0; t < m->tri_count; t++) {
        uint32_t *v = &m->tri[3 * t];
        vec3 a = v3(m->pos[3 * v[0]], m->pos[3 * v[0] + 1], m->pos[3 * v[0] + 2]);
        vec3 b = v3(m->pos[3 * v[1]], m->pos[3 * v[1] + 1], m->pos[3 * v[1] + 2]);
        vec3 c = v3(m->pos[3 * v[2]], m->pos[3 * v[2] + 1], m->pos[3 * v[2] + 2]);
        if (sign * v3_dot(v3_cross(v3_sub(b, a), v3_sub(c, a)), v3_sub(a, point)) < 0.0) {
            uint32_t tmp = v[1];
            v[1] = v[2];
            v[2] = tmp;
        }
    }
}

int sim_mesh_box(struct sim_mesh *m, double sx, double sy, double sz, uint32_t seg)
{
    uint32_t n = seg / 4 + 1;
    int rc = mesh_alloc(m, 6 * grid_verts(n, n), 12 * n * n);
    if (rc != 0)
        return rc;
    uint32_t vert = 0, tri = 0;
    for (int axis = 0; axis < 3; axis++) {
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            double s[5] = {sx, sy, sz, axis, sgn};
            add_grid(m, &vert, &tri, n, n, box_face_fn, s);
        }
    }
    m->vert_count = vert;
    m->tri_count = tri;
    /* Winding of the grids is not uniform across faces: orient each triangle outwards. */
    orient_faces(m, v3(0, 0, 0.5 * sz), 1.0);
    sim_mesh_compute_normals(m);
    return 0;
}

/* One face of the open corner: s[0] the side, s[1] 0 floor (z = 0), 1 back wall (x = -side/2),
 * 2 side wall (y = -side/2). */
static vec3 corner_face_fn(double u, double v, const double *s)
{
    double a = (u - 0.5) * s[0], b = (v - 0.5) * s[0], h = s[0];
    if (s[1] == 0.0)
        return v3(a, b, 0.0);
    if (s[1] == 1.0)
        return v3(-0.5 * h, a, (b / h + 0.5) * h);
    return v3(a, -0.5 * h, (b / h + 0.5) * h);
}

/* One face of the groove: s[0] the side, s[1] 0 floor, 1 or 2 the walls, s[2] their half angle. */
static vec3 groove_face_fn(double u, double v, const double *s)
{
    double h = s[0], a = (u - 0.5) * h, b = (v - 0.5) * h;
    if (s[1] == 0.0)
        return v3(a, b, 0.0);
    double side = s[1] == 1.0 ? 1.0 : -1.0, r = u * h; /* from the groove's edge outwards */
    return v3(-0.5 * h + r * cos(s[2]), side * r * sin(s[2]), (b / h + 0.5) * h);
}

int sim_mesh_groove(struct sim_mesh *m, double side, double opening_deg, uint32_t seg)
{
    uint32_t n = seg / 4 + 1;
    int rc = mesh_alloc(m, 3 * grid_verts(n, n), 6 * n * n);
    if (rc != 0)
        return rc;
    uint32_t vert = 0, tri = 0;
    for (int face = 0; face < 3; face++) {
        double s[3] = {side, face, 0.5 * opening_deg * M_PI / 180.0};
        add_grid(m, &vert, &tri, n, n, groove_face_fn, s);
    }
    m->vert_count = vert;
    m->tri_count = tri;
    orient_faces(m, v3(0.0, 0.0, 0.5 * side), -1.0); /* towards the groove, above the floor */
    sim_mesh_compute_normals(m);
    return 0;
}

int sim_mesh_corner(struct sim_mesh *m, double side, uint32_t seg)
{
    uint32_t n = seg / 4 + 1;
    int rc = mesh_alloc(m, 3 * grid_verts(n, n), 6 * n * n);
    if (rc != 0)
        return rc;
    uint32_t vert = 0, tri = 0;
    for (int face = 0; face < 3; face++) {
        double s[2] = {side, face};
        add_grid(m, &vert, &tri, n, n, corner_face_fn, s);
    }
    m->vert_count = vert;
    m->tri_count = tri;
    /* Every face towards the inside of the corner, where the camera and projector are. */
    orient_faces(m, v3(0.5 * side, 0.5 * side, 0.5 * side), -1.0);
    sim_mesh_compute_normals(m);
    return 0;
}

static vec3 torus_fn(double u, double v, const double *s)
{
    double phi = 2.0 * M_PI * u, th = 2.0 * M_PI * v;
    double ring = s[0] + s[1] * cos(th);
    return v3(ring * cos(phi), ring * sin(phi), s[1] + s[1] * sin(th));
}

int sim_mesh_torus(struct sim_mesh *m, double major, double minor, uint32_t seg)
{
    double shape[2] = {major, minor};
    return single_grid_mesh(m, seg, seg / 2, torus_fn, shape);
}

void sim_mesh_compute_normals(struct sim_mesh *m)
{
    memset(m->normal, 0, (size_t)m->vert_count * 3 * sizeof(float));
    for (uint32_t t = 0; t < m->tri_count; t++) {
        const uint32_t *v = &m->tri[3 * t];
        vec3 a = v3(m->pos[3 * v[0]], m->pos[3 * v[0] + 1], m->pos[3 * v[0] + 2]);
        vec3 b = v3(m->pos[3 * v[1]], m->pos[3 * v[1] + 1], m->pos[3 * v[1] + 2]);
        vec3 c = v3(m->pos[3 * v[2]], m->pos[3 * v[2] + 1], m->pos[3 * v[2] + 2]);
        vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a)); /* length = 2 * area: area weighting */
        for (int k = 0; k < 3; k++) {
            m->normal[3 * v[k]] += (float)n.x;
            m->normal[3 * v[k] + 1] += (float)n.y;
            m->normal[3 * v[k] + 2] += (float)n.z;
        }
    }
    for (uint32_t i = 0; i < m->vert_count; i++) {
        vec3 n = v3_norm(v3(m->normal[3 * i], m->normal[3 * i + 1], m->normal[3 * i + 2]));
        m->normal[3 * i] = (float)n.x;
        m->normal[3 * i + 1] = (float)n.y;
        m->normal[3 * i + 2] = (float)n.z;
    }
}

void sim_mesh_y_up_to_z_up(struct sim_mesh *m)
{
    /* (x, y, z) -> (x, -z, y): a rotation of +90 degrees about x; keeps handedness. */
    for (uint32_t i = 0; i < m->vert_count; i++) {
        float y = m->pos[3 * i + 1], z = m->pos[3 * i + 2];
        m->pos[3 * i + 1] = -z;
        m->pos[3 * i + 2] = y;
    }
}

void sim_mesh_place(struct sim_mesh *m, double height_mm)
{
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (uint32_t i = 0; i < m->vert_count; i++) {
        for (int k = 0; k < 3; k++) {
            float p = m->pos[3 * i + k];
            lo[k] = p < lo[k] ? p : lo[k];
            hi[k] = p > hi[k] ? p : hi[k];
        }
    }
    double scale = height_mm / (double)(hi[2] - lo[2]);
    double cx = 0.5 * (lo[0] + hi[0]), cy = 0.5 * (lo[1] + hi[1]);
    for (uint32_t i = 0; i < m->vert_count; i++) {
        m->pos[3 * i] = (float)((m->pos[3 * i] - cx) * scale);
        m->pos[3 * i + 1] = (float)((m->pos[3 * i + 1] - cy) * scale);
        m->pos[3 * i + 2] = (float)((m->pos[3 * i + 2] - lo[2]) * scale);
    }
    sim_mesh_compute_normals(m);
}
