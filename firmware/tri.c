/* Camera-ray / projector-plane triangulation and range-image normals, in static buffers. */
#include "tri.h"

#include "vec3.h"

#include <errno.h>

static float xyz_map[HAL_MAX_PIXELS * 3];
static float normal_map[HAL_MAX_PIXELS * 3];
/* Per projector column: plane normal in the camera frame and its offset, n . p + d = 0. */
static struct {
    vec3 normal;
    double offset;
} column_plane[HAL_MAX_PROJECTOR_WIDTH];
static struct tri_range range;

static void prepare_planes(const struct scan_calib *c)
{
    vec3 t = v3_from(c->proj_trans_mm);
    for (uint32_t col = 0; col < c->proj_width; col++) {
        /* Column centres sit on integer coordinates (pixel centre convention). */
        vec3 n_proj = v3(1.0, 0.0, -((double)col - c->proj_cx_px) / c->proj_fx_px);
        /* n_proj . (R p + t) = 0  <=>  (R^T n_proj) . p + n_proj . t = 0 */
        column_plane[col].normal = m3_tmul(c->proj_rot, n_proj);
        column_plane[col].offset = v3_dot(n_proj, t);
    }
}

int tri_range_image(const struct scan_calib *c, const struct decode_maps *maps)
{
    if (maps->width != c->cam_width || maps->height != c->cam_height ||
        c->proj_width > HAL_MAX_PROJECTOR_WIDTH)
        return -EINVAL;
    prepare_planes(c);
    range.xyz_mm = xyz_map;
    range.normal = normal_map;
    range.width = maps->width;
    range.height = maps->height;
    range.valid_count = 0;
    for (uint32_t y = 0; y < maps->height; y++) {
        for (uint32_t x = 0; x < maps->width; x++) {
            size_t i = (size_t)y * maps->width + x;
            if (maps->reason[i] != SCAN_VALID)
                continue;
            vec3 ray = v3(((double)x - c->cam_cx_px) / c->cam_fx_px,
                          ((double)y - c->cam_cy_px) / c->cam_fy_px, 1.0);
            uint16_t col = maps->column[i];
            double denom = v3_dot(column_plane[col].normal, ray);
            double s = denom != 0.0 ? -column_plane[col].offset / denom : -1.0;
            /* A grazing plane (|denom| tiny) would put the point at infinity. */
            if (s <= 0.0 || denom * denom < 1e-12 * v3_dot(ray, ray)) {
                maps->reason[i] = SCAN_INCONSISTENT;
                continue;
            }
            xyz_map[3 * i + 0] = (float)(ray.x * s);
            xyz_map[3 * i + 1] = (float)(ray.y * s);
            xyz_map[3 * i + 2] = (float)s;
            range.valid_count++;
        }
    }
    return 0;
}

static vec3 point_at(size_t i)
{
    return v3(xyz_map[3 * i], xyz_map[3 * i + 1], xyz_map[3 * i + 2]);
}

/* Tangent along one image axis from the neighbours at -step and +step that lie on the same
 * surface; falls back to a one-sided difference. Returns 0 when neither neighbour qualifies. */
static int tangent(const struct decode_maps *m, size_t i, int has_prev, int has_next, size_t step,
                   double max_jump, vec3 *out)
{
    vec3 p = point_at(i);
    int ok_prev = has_prev && m->reason[i - step] == SCAN_VALID &&
                  fabs(xyz_map[3 * (i - step) + 2] - p.z) <= max_jump;
    int ok_next = has_next && m->reason[i + step] == SCAN_VALID &&
                  fabs(xyz_map[3 * (i + step) + 2] - p.z) <= max_jump;
    if (ok_prev && ok_next)
        *out = v3_sub(point_at(i + step), point_at(i - step));
    else if (ok_next)
        *out = v3_sub(point_at(i + step), p);
    else if (ok_prev)
        *out = v3_sub(p, point_at(i - step));
    else
        return 0;
    return 1;
}

int tri_normals(const struct decode_maps *m, double max_depth_jump_mm)
{
    const uint32_t w = m->width, h = m->height;
    uint32_t valid = 0;
    for (uint32_t y = 0; y < h; y++) {
        for (uint32_t x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            if (m->reason[i] != SCAN_VALID)
                continue;
            vec3 du, dv;
            if (!tangent(m, i, x > 0, x + 1 < w, 1, max_depth_jump_mm, &du) ||
                !tangent(m, i, y > 0, y + 1 < h, w, max_depth_jump_mm, &dv)) {
                m->reason[i] = SCAN_INCONSISTENT;
                continue;
            }
            vec3 n = v3_norm(v3_cross(du, dv));
            if (v3_dot(n, point_at(i)) > 0.0) /* face the camera */
                n = v3_scale(n, -1.0);
            normal_map[3 * i + 0] = (float)n.x;
            normal_map[3 * i + 1] = (float)n.y;
            normal_map[3 * i + 2] = (float)n.z;
            valid++;
        }
    }
    range.valid_count = valid;
    return 0;
}

const struct tri_range *tri_get_range(void)
{
    return &range;
}
