/* Intrinsic colour: dark-frame offset, single-light, constant and multiple-light compensation. */
#include "colour.h"

#include "vec3.h"

#include <errno.h>
#include <string.h>

/* Ca per channel: the mean of the dark frame over the pixels that have depth (the object), so
 * that ambient light on the object counts and the background does not. */
static void channel_offset(const struct decode_maps *m, const uint8_t *dark, double ca[3])
{
    double sum[3] = {0, 0, 0};
    size_t n = (size_t)m->width * m->height, count = 0;
    for (size_t i = 0; i < n; i++) {
        if (m->reason[i] != SCAN_VALID)
            continue;
        for (int k = 0; k < 3; k++)
            sum[k] += dark[3 * i + (size_t)k];
        count++;
    }
    for (int k = 0; k < 3; k++)
        ca[k] = count ? sum[k] / count : 0.0;
}

/* cos(theta) of a source at @p src for surface point p with normal n, and the falloff factor. */
static double incidence(const struct colour_params *prm, vec3 p, vec3 n, vec3 src, double *fall)
{
    vec3 to = v3_sub(src, p);
    double d = v3_len(to);
    *fall = prm->falloff ? (d / prm->reference_mm) * (d / prm->reference_mm) : 1.0;
    return v3_dot(n, v3_scale(to, 1.0 / d));
}

static int saturated(const uint8_t *px, uint32_t level)
{
    return px[0] >= level || px[1] >= level || px[2] >= level;
}

int colour_compute(const struct colour_params *prm, const struct scan_calib *c,
                   const struct decode_maps *m, const struct tri_range *r, const uint8_t *white,
                   const uint8_t *const *lights, uint8_t *albedo, float *confidence)
{
    size_t n = (size_t)m->width * m->height;
    const uint8_t *dark = lights != NULL ? lights[COLOUR_FRAME_DARK] : NULL;
    if (prm->method != COLOUR_NONE && dark == NULL)
        return -EINVAL;
    if (prm->method == COLOUR_UNIFORM && lights[COLOUR_FRAME_ALL] == NULL)
        return -EINVAL;
    for (uint32_t l = 0; prm->method == COLOUR_MULTI && l < c->light_count; l++)
        if (lights[COLOUR_FRAME_LIGHT0 + l] == NULL)
            return -EINVAL;
    double ca_channel[3] = {0, 0, 0};
    if (dark != NULL)
        channel_offset(m, dark, ca_channel);
    vec3 proj = v3_scale(m3_tmul(c->proj_rot, v3_from(c->proj_trans_mm)), -1.0);
    for (size_t i = 0; i < n; i++) {
        memcpy(&albedo[3 * i], &white[3 * i], 3); /* raw colour unless compensated below */
        confidence[i] = prm->method == COLOUR_NONE && m->reason[i] == SCAN_VALID;
        if (prm->method == COLOUR_NONE || m->reason[i] != SCAN_VALID)
            continue;
        vec3 p = v3(r->xyz_mm[3 * i], r->xyz_mm[3 * i + 1], r->xyz_mm[3 * i + 2]);
        vec3 nn = v3(r->normal[3 * i], r->normal[3 * i + 1], r->normal[3 * i + 2]);
        vec3 view = v3_norm(v3_scale(p, -1.0));
        double ca[3];
        for (int k = 0; k < 3; k++)
            ca[k] = prm->ca_per_pixel ? dark[3 * i + (size_t)k] : ca_channel[k];
        double num[3] = {0, 0, 0}, den = 0.0;
        if (prm->method == COLOUR_SINGLE) { /* eq. 4 */
            double fall, ct = incidence(prm, p, nn, proj, &fall);
            if (ct < prm->min_cos || saturated(&white[3 * i], prm->saturation_dn))
                continue;
            for (int k = 0; k < 3; k++)
                num[k] = (white[3 * i + (size_t)k] - ca[k]) * fall;
            den = ct;
        } else if (prm->method == COLOUR_UNIFORM) { /* method 2 */
            const uint8_t *all = &lights[COLOUR_FRAME_ALL][3 * i];
            if (saturated(all, prm->saturation_dn))
                continue;
            for (int k = 0; k < 3; k++)
                num[k] = all[k] - ca[k];
            den = 1.0;
        } else { /* eq. 6, with shadowed lights weighted 0 */
            for (uint32_t l = 0; l < c->light_count; l++) {
                const uint8_t *px = &lights[COLOUR_FRAME_LIGHT0 + l][3 * i];
                double fall, ct = incidence(prm, p, nn, v3_from(c->light_pos_mm[l]), &fall);
                double lum = (px[0] + px[1] + px[2]) / 3.0 - (ca[0] + ca[1] + ca[2]) / 3.0;
                if (ct < prm->min_cos || lum <= prm->shadow_dn ||
                    saturated(px, prm->saturation_dn))
                    continue;
                vec3 s = v3_norm(v3_sub(v3_from(c->light_pos_mm[l]), p));
                vec3 refl = v3_sub(v3_scale(nn, 2.0 * v3_dot(s, nn)), s);
                double ca_ = v3_dot(refl, view);
                double w = pow(1.0 - pow(ca_ > 0.0 ? ca_ : 0.0, prm->ke), prm->ko);
                for (int k = 0; k < 3; k++)
                    num[k] += (px[k] - ca[k]) * fall * w;
                den += ct * w;
            }
        }
        if (den <= 1e-6)
            continue;
        for (int k = 0; k < 3; k++) {
            double v = num[k] / den * prm->white_scale[k] * 255.0;
            albedo[3 * i + (size_t)k] = (uint8_t)(v < 0.0 ? 0.0 : v > 255.0 ? 255.0 : v + 0.5);
        }
        confidence[i] = (float)(den > 1.0 ? 1.0 : den);
    }
    return 0;
}
