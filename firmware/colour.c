/* Intrinsic colour: dark-frame offset, single-light, constant and multiple-light compensation. */
#include "colour.h"

#include "reflect.h"
#include "vec3.h"

#include <errno.h>
#include <string.h>

static uint32_t add_frame(struct colour_layout *l, uint32_t lights_mask, uint32_t exposure_us)
{
    l->lights_mask[l->count] = lights_mask;
    l->exposure_us[l->count] = exposure_us;
    l->dark_of[l->count] = 0;
    return l->count++;
}

/* The dark frame at @p exposure_us: Ca holds the black offset, which does not change with the
 * exposure, and the ambient light, which does; so each exposure gets its own dark frame. */
static uint32_t dark_at(struct colour_layout *l, uint32_t exposure_us)
{
    for (uint32_t k = 0; k < l->count; k++)
        if (l->lights_mask[k] == 0 && l->exposure_us[k] == exposure_us)
            return k;
    uint32_t k = add_frame(l, 0, exposure_us);
    l->dark_of[k] = k;
    return k;
}

void colour_layout(const struct colour_params *p, uint32_t light_count, struct colour_layout *out)
{
    memset(out, 0, sizeof(*out));
    if ((p->taken_with ? p->taken_with : p->method) == COLOUR_NONE)
        return;
    uint32_t all_us = p->all_lights_exposure_us ? p->all_lights_exposure_us : p->exposure_us;
    uint32_t one_us = p->light_exposure_us ? p->light_exposure_us : p->exposure_us;
    add_frame(out, 0, p->exposure_us); /* COLOUR_FRAME_DARK */
    add_frame(out, (1u << light_count) - 1u, all_us);
    for (uint32_t l = 0; l < light_count; l++)
        add_frame(out, 1u << l, one_us);
    /* taken whatever the method, so one scan serves every method; scan_check refuses more
     * lights than the build can bracket */
    if (p->bracket > 1 && light_count <= COLOUR_MAX_BRACKETED)
        for (uint32_t l = 0; l < light_count; l++)
            out->long_of[COLOUR_FRAME_LIGHT0 + l] = add_frame(out, 1u << l, one_us * p->bracket);
    uint32_t lit = out->count;
    for (uint32_t k = COLOUR_FRAME_ALL; k < lit; k++)
        out->dark_of[k] = dark_at(out, out->exposure_us[k]);
}

int colour_needs_frame(const struct colour_params *p, const struct colour_layout *l, uint32_t k)
{
    if (k >= l->count)
        return 0;
    switch (p->method) {
    case COLOUR_NONE:
        return 0;
    case COLOUR_SINGLE: /* the projector's white (a pattern frame) less the dark frame */
        return k == COLOUR_FRAME_DARK;
    case COLOUR_UNIFORM:
        return k == COLOUR_FRAME_ALL || k == l->dark_of[COLOUR_FRAME_ALL];
    default: /* multi, fit */
        for (uint32_t m = COLOUR_FRAME_LIGHT0; m < l->count; m++)
            if (l->lights_mask[m] != 0 && (m == k || l->dark_of[m] == k))
                return 1;
        return 0;
    }
}

/* Sums over a frame's pixels that have depth, in integers (exact, so the same on any number
 * of threads): the count and, per channel, the frame's bytes y and, for fit_ambient, the
 * albedo bytes x of a first pass, x^2 and x y over its confident pixels. */
struct pixel_sums {
    uint64_t n, x[3], y[3], xx[3], xy[3];
};

struct sum_parts {
    const struct decode_maps *m;
    const uint8_t *frame;
    const uint8_t *albedo;   /* NULL: the frame alone (channel_offset) */
    const float *confidence; /* with albedo: only pixels with an estimate */
    size_t pixels;
    unsigned parts;
    struct pixel_sums sum[HAL_MAX_PARTS];
};

static void sum_part(void *arg, unsigned k)
{
    struct sum_parts *p = arg;
    struct pixel_sums t = {0};
    for (size_t i = p->pixels * k / p->parts; i < p->pixels * (k + 1u) / p->parts; i++) {
        if (p->m->reason[i] != SCAN_VALID || (p->albedo != NULL && p->confidence[i] <= 0.0f))
            continue;
        t.n++;
        for (int c = 0; c < 3; c++) {
            uint64_t y = p->frame[3 * i + (size_t)c];
            uint64_t x = p->albedo != NULL ? p->albedo[3 * i + (size_t)c] : 0u;
            t.y[c] += y, t.x[c] += x, t.xx[c] += x * x, t.xy[c] += x * y;
        }
    }
    p->sum[k] = t;
}

/* The sums of sum_part over the whole frame, its parts split across @p threads. */
static void pixel_sums(const struct hal_thread *threads, const struct decode_maps *m,
                       const uint8_t *frame, const uint8_t *albedo, const float *confidence,
                       struct pixel_sums *out)
{
    static struct sum_parts p; /* 4 KiB of sums: one view is coloured at a time */
    p = (struct sum_parts){.m = m,
                           .frame = frame,
                           .albedo = albedo,
                           .confidence = confidence,
                           .pixels = (size_t)m->width * m->height,
                           .parts = hal_thread_parts(threads, HAL_MAX_PARTS)};
    hal_thread_run(threads, p.parts, sum_part, &p);
    *out = (struct pixel_sums){0};
    for (unsigned k = 0; k < p.parts; k++) {
        out->n += p.sum[k].n;
        for (int c = 0; c < 3; c++) {
            out->x[c] += p.sum[k].x[c], out->y[c] += p.sum[k].y[c];
            out->xx[c] += p.sum[k].xx[c], out->xy[c] += p.sum[k].xy[c];
        }
    }
}

/* Ca per channel: the mean of a dark frame over the pixels that have depth (the object), so
 * that ambient light on the object counts and the background does not. */
static void channel_offset(const struct hal_thread *threads, const struct decode_maps *m,
                           const uint8_t *dark, double ca[3])
{
    struct pixel_sums t;
    pixel_sums(threads, m, dark, NULL, NULL, &t);
    for (int k = 0; k < 3; k++)
        ca[k] = t.n ? (double)t.y[k] / (double)t.n : 0.0;
}

/* What frame_light() needs: the frames in colour_layout() order and each dark frame's Ca:
 * ca_channel + ca_slope x the pixel's albedo from a first pass (ca = albedo; else slope 0). */
struct frame_ctx {
    const struct colour_params *prm;
    const struct colour_layout *lay;
    const uint8_t *const *frames;
    double ca_channel[COLOUR_MAX_FRAMES][3];
    double ca_slope[COLOUR_MAX_FRAMES][3];
    /* each dark frame's Ca for every albedo byte, ca_channel + ca_slope x byte / 255 (a pixel's
     * three lights read it up to 24 times: a table lookup, not a division, each time) */
    double ca_of_albedo[COLOUR_MAX_FRAMES][3][256];
    double gain[COLOUR_MAX_FRAMES]; /* the camera's exposure over the frame's */
    const uint8_t *albedo;          /* the first pass's albedo bytes (ca = albedo) */
    int ke_whole, ko_whole; /* eq. 6's exponents where whole, up to 64; -1: not (whole_power) */
};

/* @p e as power() takes it: whole up to 64 (the exponents of eq. 6 as people set them, 10 and
 * 4 by default), else -1. Told once a view, not at each of its 7 million weights (0.8% of a
 * re-processing's instructions). */
static int whole_power(double e)
{
    return e >= 0.0 && e <= 64.0 && e == (double)(int)e ? (int)e : -1;
}

/* The tables of @p f from its Ca and the layout's exposures (again whenever the Ca changes);
 * every slot, as frame_light would have computed it for any frame it is asked for. */
static void frame_tables(struct frame_ctx *f)
{
    for (uint32_t k = 0; k < COLOUR_MAX_FRAMES; k++) {
        f->gain[k] = (double)f->prm->exposure_us / f->lay->exposure_us[k];
        for (int c = 0; c < 3 && f->lay->dark_of[k] == k; c++)
            for (int a = 0; a < 256; a++)
                f->ca_of_albedo[k][c][a] = f->ca_channel[k][c] + f->ca_slope[k][c] * a / 255.0;
    }
}

/* A channel of RGB pixel @p px at or above the saturation level. */
static int clipped(const struct colour_params *prm, const uint8_t *px)
{
    return px[0] >= prm->saturation_dn || px[1] >= prm->saturation_dn ||
           px[2] >= prm->saturation_dn;
}

/* Frame k's light at pixel i (@p px) with its Ca taken off, in grey levels at the camera's
 * exposure, so that one white reference serves every exposure. @retval 0 when a channel is
 * saturated (@p out is filled all the same), 1 otherwise */
static inline int frame_light(const struct frame_ctx *f, uint32_t k, const uint8_t *px, size_t i,
                              double out[3])
{
    const uint32_t d = f->lay->dark_of[k];
    const double gain = f->gain[k];
    double ca[3];
    /* every byte read before out is written: the frames are bytes, which may alias anything,
     * and would be read again after each store */
    if (f->prm->ca == COLOUR_CA_PIXEL) {
        const uint8_t *dark = &f->frames[d][3 * i];
        ca[0] = dark[0], ca[1] = dark[1], ca[2] = dark[2];
    } else {
        const uint8_t *albedo = &f->albedo[3 * i];
        for (int c = 0; c < 3; c++)
            ca[c] = f->ca_of_albedo[d][c][albedo[c]];
    }
    const int v[3] = {px[0], px[1], px[2]};
    for (int c = 0; c < 3; c++)
        out[c] = (v[c] - ca[c]) * gain;
    return !clipped(f->prm, px);
}

/* A source as surface point @p p sees it: the unit vector toward it and its distance. */
struct toward {
    vec3 dir;
    double dist_mm;
};

static struct toward toward(vec3 p, vec3 src)
{
    vec3 to = v3_sub(src, p);
    double d = v3_len(to);
    return (struct toward){v3_scale(to, 1.0 / d), d};
}

/* cos(theta) of a source in direction @p s for a surface of normal n, and the falloff factor. */
static double incidence(const struct colour_params *prm, vec3 n, struct toward s, double *fall)
{
    double d = s.dist_mm;
    *fall = prm->falloff ? (d / prm->reference_mm) * (d / prm->reference_mm) : 1.0;
    return v3_dot(n, s.dir);
}

/* @p x to the power @p e: by repeated squaring where @p whole (whole_power) is one (pow() cost 5%
 * of a re-processing's CPU), else pow. */
static inline double power(double x, double e, int whole)
{
    if (whole < 0)
        return pow(x, e);
    double r = 1.0;
    for (unsigned k = (unsigned)whole; k != 0; k >>= 1, x *= x)
        if (k & 1u)
            r *= x;
    return r;
}

/* The unit vector from surface point @p p to the camera (at the origin). */
static vec3 view_of(vec3 p)
{
    return v3_norm(v3_scale(p, -1.0));
}

/* How far the mirror reflection of a source in direction @p s at a surface of normal n is from
 * the camera (direction @p view), as the weight of Jost et al., eq. 6: (1 - cos^ke alpha)^ko;
 * 0 in the middle of a highlight, 1 away from it. */
static double specular_weight(const struct frame_ctx *f, vec3 n, vec3 view, vec3 s)
{
    const struct colour_params *prm = f->prm;
    vec3 refl = v3_sub(v3_scale(n, 2.0 * v3_dot(s, n)), s);
    double cos_a = v3_dot(refl, view);
    return power(1.0 - power(cos_a > 0.0 ? cos_a : 0.0, prm->ke, f->ke_whole), prm->ko,
                 f->ko_whole);
}

/* Albedo 0..1 as the stored byte 0..255, rounded and clamped. */
static uint8_t albedo_byte(double albedo)
{
    double v = albedo * 255.0;
    return (uint8_t)(v < 0.0 ? 0.0 : v > 255.0 ? 255.0 : v + 0.5);
}

/* No compensation: the raw colour, white-balanced only (the white reference's scale; the
 * default 1/255 keeps it as it is). */
static void white_balance(const struct colour_params *prm, uint8_t *rgb)
{
    for (int k = 0; k < 3; k++)
        rgb[k] = albedo_byte(rgb[k] * prm->white_scale[k]);
}

/* Each light's signal at a valid pixel, as the multi and fit methods take it: read in its
 * longer frame where that one does not saturate ([colour] bracket), so that dark paint rises
 * above the noise; Ca, the falloff and the light's gain taken out (lit = rho cos(theta) x the
 * white reference's inverse for a matte surface). @c used: the lights that reach the pixel. */
struct light_signals {
    double lit[HAL_MAX_LIGHTS][3], cosine[HAL_MAX_LIGHTS], weight[HAL_MAX_LIGHTS];
    uint32_t used;
};

static void light_signals(const struct frame_ctx *f, const struct scan_calib *c, size_t i, vec3 p,
                          vec3 nn, vec3 view, int relaxed, struct light_signals *out)
{
    const struct colour_params *prm = f->prm;
    const double min_cos = relaxed ? 0.02 : prm->min_cos;
    double est[HAL_MAX_LIGHTS], best = 0.0;
    out->used = 0;
    for (uint32_t l = 0; l < c->light_count; l++) {
        struct toward s = toward(p, v3_from(c->light_pos_mm[l]));
        double fall, ct = incidence(prm, nn, s, &fall);
        est[l] = -1.0;
        if (ct < min_cos) /* turned away from it: its frame is not read */
            continue;
        uint32_t k = COLOUR_FRAME_LIGHT0 + l, kl = f->lay->long_of[k];
        if (kl != 0 && !clipped(prm, &f->frames[kl][3 * i]))
            k = kl;
        double *lit = out->lit[l];
        int ok = frame_light(f, k, &f->frames[k][3 * i], i, lit);
        /* the signal in grey levels of the frame it was read in: below shadow_dn it is noise */
        double raw = (lit[0] + lit[1] + lit[2]) / 3.0 * f->lay->exposure_us[k] / prm->exposure_us;
        if ((!ok && !relaxed) || raw <= prm->shadow_dn)
            continue;
        out->weight[l] = specular_weight(f, nn, view, s.dir);
        /* a brighter light gives more signal for the same albedo: its gain takes that out */
        double gain = c->light_gain[l] > 0.0 ? c->light_gain[l] : 1.0;
        for (int ch = 0; ch < 3; ch++)
            lit[ch] *= fall / gain;
        out->cosine[l] = ct;
        est[l] = (lit[0] + lit[1] + lit[2]) / (3.0 * ct); /* this light's albedo */
        if (out->weight[l] > 0.5 && est[l] > best)
            best = est[l];
    }
    /* cast shadow: what reaches the pixel is light from other surfaces, far below what the
     * lights that do reach it say (dark paint is dark under every light) */
    for (uint32_t l = 0; l < c->light_count; l++)
        if (est[l] >= 0.0 && est[l] >= prm->shadow_ratio * best)
            out->used |= 1u << l;
}

/* Eq. 6 over the lights that reach the pixel: the numerator per channel (@p num) and, returned,
 * the denominator sum cos(theta_i) w_i. */
static double multi_sum(const struct light_signals *ls, uint32_t light_count, double num[3])
{
    double den = 0.0;
    num[0] = num[1] = num[2] = 0.0;
    for (uint32_t l = 0; l < light_count; l++) {
        if (!(ls->used >> l & 1u))
            continue;
        for (int ch = 0; ch < 3; ch++)
            num[ch] += ls->lit[l][ch] * ls->weight[l];
        den += ls->cosine[l] * ls->weight[l];
    }
    return den;
}

/* The angle between normal @p n and the half vector of light @p light_pos and the camera
 * (at the origin, direction @p view from @p p): alpha of the lobe (reflect.h). */
static double half_angle(vec3 p, vec3 n, vec3 view, const double light_pos[3])
{
    vec3 to = toward(p, v3_from(light_pos)).dir;
    double nh = v3_dot(n, v3_norm(v3_add(to, view)));
    return acos(nh > 1.0 ? 1.0 : nh < -1.0 ? -1.0 : nh);
}

/* cos(theta_d) at @p p: half the angle between the light at @p light_pos and the camera (the
 * unit vector @p view) */
static double half_cos(vec3 p, vec3 view, const double light_pos[3])
{
    return reflect_cos_d(v3_dot(toward(p, v3_from(light_pos)).dir, view));
}

/* Albedo estimate of valid pixel i: numerator per channel and the denominator (0: none), and
 * how much the fusion may trust it (@p confidence, 0..; not clamped). @p relaxed: the best
 * effort for a pixel without a reliable estimate (grazing or saturated light still used). */
static double pixel_estimate(const struct frame_ctx *f, const struct scan_calib *c, vec3 proj,
                             const uint8_t *white, size_t i, vec3 p, vec3 nn, vec3 view,
                             int relaxed, double num[3], double *confidence)
{
    const struct colour_params *prm = f->prm;
    const double min_cos = relaxed ? 0.02 : prm->min_cos;
    double den = 0.0, light[3];
    num[0] = num[1] = num[2] = 0.0;
    *confidence = 0.0;
    if (prm->method == COLOUR_SINGLE) { /* eq. 4 */
        struct toward s = toward(p, proj);
        double fall, ct = incidence(prm, nn, s, &fall);
        int ok = frame_light(f, COLOUR_FRAME_DARK, &white[3 * i], i, light);
        if (ct < min_cos || (!ok && !relaxed))
            return 0.0;
        for (int k = 0; k < 3; k++)
            num[k] = light[k] * fall;
        *confidence = ct * specular_weight(f, nn, view, s.dir);
        return ct;
    }
    if (prm->method == COLOUR_UNIFORM) { /* method 2 */
        int ok = frame_light(f, COLOUR_FRAME_ALL, &f->frames[COLOUR_FRAME_ALL][3 * i], i, num);
        int lit = (num[0] + num[1] + num[2]) / 3.0 > prm->shadow_dn; /* not every light shadowed */
        /* the estimate cannot take a highlight out, so a pixel near any light's mirror
         * direction is trusted less: the fusion takes its colour from another view */
        *confidence = 1.0;
        for (uint32_t l = 0; l < c->light_count; l++) {
            vec3 src = v3_from(c->light_pos_mm[l]);
            double w = specular_weight(f, nn, view, toward(p, src).dir);
            if (v3_dot(nn, v3_sub(src, p)) > 0.0 && w < *confidence)
                *confidence = w;
        }
        return (ok && lit) || relaxed ? 1.0 : 0.0;
    }
    struct light_signals ls;
    light_signals(f, c, i, p, nn, view, relaxed, &ls);
    den = multi_sum(&ls, c->light_count, num);
    *confidence = den;
    return den;
}

/* What fit_pixel needs across the pixels of a pass: the model (NULL before it is fitted) and,
 * while the pool collects, every how many valid pixels a sample is taken. */
struct fit_state {
    struct reflect_pool *pool; /* where samples go while it collects; NULL: no reflectance */
    const struct reflect_model *model;
    int collect;
    uint32_t stride, seen;
};

/* The lobe is narrow: a normal's noise (a few degrees from the range image) blurs it as much as
 * the material's roughness does, and the fit would take that for a rougher, weaker lobe. The
 * fit's angles use the mean of the valid normals within LOBE_NORMAL_RADIUS pixels (about
 * 1.5 mm on the object here, far below its curvature), both when sampling and when applying. */
#define LOBE_NORMAL_RADIUS 6
static vec3 lobe_normal(const struct decode_maps *m, const struct tri_range *r, size_t i)
{
    long x0 = (long)(i % m->width), y0 = (long)(i / m->width);
    vec3 sum = v3(0, 0, 0);
    for (long y = y0 - LOBE_NORMAL_RADIUS; y <= y0 + LOBE_NORMAL_RADIUS; y++)
        for (long x = x0 - LOBE_NORMAL_RADIUS; x <= x0 + LOBE_NORMAL_RADIUS; x++) {
            if (x < 0 || y < 0 || x >= (long)m->width || y >= (long)m->height)
                continue;
            size_t j = (size_t)y * m->width + (size_t)x;
            if (m->reason[j] == SCAN_VALID)
                sum = v3_add(sum, v3(r->normal[3 * j], r->normal[3 * j + 1], r->normal[3 * j + 2]));
        }
    return v3_norm(sum);
}

/* One sample for the pool: pixel at @p p (normal @p nn) with each used light's white-referenced
 * signal and its angles (reflect.h). */
static void add_sample(struct reflect_pool *pool, const struct colour_params *prm,
                       const struct scan_calib *c, vec3 p, vec3 nn, const struct light_signals *ls,
                       const double rho0[3])
{
    struct reflect_obs o;
    memset(&o, 0, sizeof(o));
    vec3 view = view_of(p);
    o.cos_r = (float)v3_dot(nn, view);
    o.lights = ls->used;
    for (int ch = 0; ch < 3; ch++)
        o.rho0[ch] = (float)rho0[ch];
    for (uint32_t l = 0; l < c->light_count; l++) {
        if (!(ls->used >> l & 1u))
            continue;
        o.alpha[l] = (float)half_angle(p, nn, view, c->light_pos_mm[l]);
        o.cos_d[l] = (float)half_cos(p, view, c->light_pos_mm[l]);
        o.cos_i[l] = (float)ls->cosine[l];
        for (int ch = 0; ch < 3; ch++)
            o.signal[l][ch] = (float)(ls->lit[l][ch] * prm->white_scale[ch]);
    }
    reflect_add(pool, &o);
}

/* [colour] method = fit at valid pixel i: before the lobes are known, the multi estimate (and a
 * sample for the pool now and then); after, the diffuse colour with the pixel's cluster's lobe
 * taken off each light: rho = sum w (S_l - K g_l) cos_l / sum w cos_l^2, w as eq. 6 (the lobe
 * takes out what the weights leave: the broad sheen of metals and satin). */
static void fit_pixel(const struct frame_ctx *f, const struct scan_calib *c, struct fit_state *fs,
                      const struct decode_maps *m, const struct tri_range *r, size_t i, vec3 p,
                      vec3 nn, uint8_t out[3], float *confidence)
{
    const struct colour_params *prm = f->prm;
    struct light_signals ls;
    int relaxed = 0;
    vec3 view = view_of(p);
    light_signals(f, c, i, p, nn, view, 0, &ls);
    if (ls.used == 0) { /* a best effort, weighing nothing (as multi) */
        light_signals(f, c, i, p, nn, view, 1, &ls);
        relaxed = 1;
    }
    double num[3], rho0[3], den = multi_sum(&ls, c->light_count, num);
    if (den <= 1e-6) {
        memset(out, 0, 3);
        *confidence = COLOUR_NO_ESTIMATE;
        return;
    }
    for (int ch = 0; ch < 3; ch++)
        rho0[ch] = num[ch] / den * prm->white_scale[ch];
    *confidence = relaxed ? 0.0f : (float)(den > 1.0 ? 1.0 : den);
    if (fs->model == NULL) {
        for (int ch = 0; ch < 3; ch++)
            out[ch] = albedo_byte(rho0[ch]);
        if (fs->collect && !relaxed && fs->seen++ % fs->stride == 0)
            add_sample(fs->pool, prm, c, p, lobe_normal(m, r, i), &ls, rho0);
        return;
    }
    const struct reflect_cluster *cl = &fs->model->cluster[reflect_cluster_of(fs->model, rho0)];
    vec3 ln = lobe_normal(m, r, i);
    double cos_r = v3_dot(ln, view), sp[HAL_MAX_LIGHTS][3], ct[HAL_MAX_LIGHTS], rho[3];
    for (uint32_t l = 0; l < c->light_count; l++) {
        reflect_specular(cl, half_angle(p, ln, view, c->light_pos_mm[l]), cos_r, sp[l]);
        if (ls.used >> l & 1u) /* the diffuse basis, what rho multiplies (Lambert's or Burley's) */
            ct[l] = reflect_diffuse(cl, ls.cosine[l], cos_r, half_cos(p, view, c->light_pos_mm[l]));
    }
    memcpy(rho, rho0, sizeof(rho));
    /* twice: each light weighs by eq. 6 and by the share of its signal the diffuse part is
     * (as the last estimate has it), so that where the lobe is most of the light (dark paint
     * on a metal) an error in the lobe does not become the colour */
    double share_sum = 0.0, share_den = 0.0;
    for (int pass = 0; pass < 2; pass++) {
        double fit_num[3] = {0, 0, 0}, fit_den = 0.0;
        double rho_grey = fmax(1e-3, (rho[0] + rho[1] + rho[2]) / 3.0);
        share_sum = share_den = 0.0;
        for (uint32_t l = 0; l < c->light_count; l++) {
            if (!(ls.used >> l & 1u))
                continue;
            double sp_grey = (sp[l][0] + sp[l][1] + sp[l][2]) / 3.0;
            double share = rho_grey * ct[l] / (rho_grey * ct[l] + sp_grey);
            double w = ls.weight[l] * share * share;
            for (int ch = 0; ch < 3; ch++)
                fit_num[ch] += w * (ls.lit[l][ch] * prm->white_scale[ch] - sp[l][ch]) * ct[l];
            fit_den += w * ct[l] * ct[l];
            share_sum += ls.weight[l] * ct[l] * share, share_den += ls.weight[l] * ct[l];
        }
        for (int ch = 0; ch < 3 && fit_den > 1e-12; ch++)
            rho[ch] = fmax(0.0, fit_num[ch] / fit_den);
    }
    for (int ch = 0; ch < 3; ch++)
        out[ch] = albedo_byte(rho[ch]);
    /* the colour is what is left of the light once the lobe is taken off: where that is a small
     * part of it, a view that sees less sheen there is the better one for the fusion */
    if (share_den > 0.0)
        *confidence *= (float)(share_sum / share_den);
}

/* One pass over the pixels of a view with the Ca of @p f, or part of them (pixels i0 .. i1 - 1):
 * albedo and confidence of every valid pixel. */
struct pass {
    const struct frame_ctx *f;
    const struct scan_calib *c;
    const struct decode_maps *m;
    const struct tri_range *r;
    const uint8_t *white;
    uint8_t *albedo;
    float *confidence;
    struct fit_state fs;
    vec3 proj;
    size_t pixels;
    unsigned parts;
    int again; /* the second pass (ca = albedo): a pixel without depth keeps what the first gave */
};

static void pass_pixels(struct pass *ps, size_t i0, size_t i1)
{
    const struct frame_ctx *f = ps->f;
    const struct colour_params *prm = f->prm;
    const struct scan_calib *c = ps->c;
    const struct decode_maps *m = ps->m;
    const struct tri_range *r = ps->r;
    const uint8_t *white = ps->white;
    uint8_t *albedo = ps->albedo;
    float *confidence = ps->confidence;
    for (size_t i = i0; i < i1; i++) {
        if (prm->method == COLOUR_NONE || m->reason[i] != SCAN_VALID) {
            if (ps->again)
                continue;
            memcpy(&albedo[3 * i], &white[3 * i], 3); /* the raw colour */
            /* trusted where valid, but not where the white frame clipped (a highlight now has
             * depth, its colour is blown out): other views colour it if they can */
            confidence[i] = prm->method == COLOUR_NONE && m->reason[i] == SCAN_VALID &&
                            !clipped(prm, &white[3 * i]);
            if (prm->method == COLOUR_NONE && m->reason[i] == SCAN_VALID)
                white_balance(prm, &albedo[3 * i]);
            continue;
        }
        /* from here on pixel i's albedo is written only after its estimate, which may read the
         * first pass's value there (ca = albedo): the passes share one buffer */
        vec3 p = v3(r->xyz_mm[3 * i], r->xyz_mm[3 * i + 1], r->xyz_mm[3 * i + 2]);
        vec3 nn = v3(r->normal[3 * i], r->normal[3 * i + 1], r->normal[3 * i + 2]);
        if (prm->method == COLOUR_FIT) {
            fit_pixel(f, c, &ps->fs, m, r, i, p, nn, &albedo[3 * i], &confidence[i]);
            continue;
        }
        vec3 view = view_of(p);
        double num[3], trust;
        double den = pixel_estimate(f, c, ps->proj, white, i, p, nn, view, 0, num, &trust);
        float conf = (float)(trust > 1.0 ? 1.0 : trust);
        if (den <= 1e-6) { /* no reliable estimate: a best effort that weighs nothing in the
                              fusion unless no view has better (raw colour is not an albedo) */
            den = pixel_estimate(f, c, ps->proj, white, i, p, nn, view, 1, num, &trust);
            conf = 0.0f;
        }
        if (den <= 1e-6) { /* no estimate at all: no colour, rather than the raw one (which
                              holds the offset Ca and the light's shading); the fusion leaves
                              it out and the mesh takes its neighbours' colour */
            memset(&albedo[3 * i], 0, 3);
            confidence[i] = COLOUR_NO_ESTIMATE;
            continue;
        }
        for (int k = 0; k < 3; k++)
            albedo[3 * i + (size_t)k] = albedo_byte(num[k] / den * prm->white_scale[k]);
        confidence[i] = conf;
    }
}

/* Part @p k of the pass's pixels (each pixel reads and writes only its own). */
static void pass_part(void *arg, unsigned k)
{
    struct pass *ps = arg;
    pass_pixels(ps, ps->pixels * k / ps->parts, ps->pixels * (k + 1u) / ps->parts);
}

static void compute_pass(const struct frame_ctx *f, const struct hal_thread *threads,
                         const struct scan_calib *c, const struct decode_maps *m,
                         const struct tri_range *r, const uint8_t *white, uint8_t *albedo,
                         float *confidence, struct reflect_pool *pool, int again, int last)
{
    struct pass ps = {.f = f,
                      .c = c,
                      .m = m,
                      .r = r,
                      .white = white,
                      .albedo = albedo,
                      .confidence = confidence,
                      .fs = {pool, pool != NULL ? reflect_model(pool) : NULL,
                             pool != NULL && last && reflect_collecting(pool),
                             pool != NULL ? reflect_stride(pool, r->valid_count) : UINT32_MAX, 0},
                      .proj = v3_scale(m3_tmul(c->proj_rot, v3_from(c->proj_trans_mm)), -1.0),
                      .pixels = (size_t)m->width * m->height,
                      .parts = hal_thread_parts(threads, 64),
                      .again = again};
    if (f->prm->method == COLOUR_FIT) { /* its samples are kept in pixel order: one thread */
        pass_pixels(&ps, 0, ps.pixels);
        return;
    }
    hal_thread_run(threads, ps.parts, pass_part, &ps);
}

/* ca = albedo: each dark frame's value at a confident pixel, per channel, as offset + slope x
 * the pixel's albedo (least squares over the object): the black offset and the ambient light
 * the paint reflects. */
static void fit_ambient(struct frame_ctx *f, const struct hal_thread *threads,
                        const struct decode_maps *m, const uint8_t *albedo, const float *confidence,
                        uint32_t k)
{
    struct pixel_sums t;
    pixel_sums(threads, m, f->frames[k], albedo, confidence, &t);
    /* x = albedo byte / 255, y = the dark frame's byte */
    double s1 = (double)t.n;
    for (int c = 0; c < 3; c++) {
        double sx = (double)t.x[c] / 255.0, sy = (double)t.y[c];
        double sxx = (double)t.xx[c] / (255.0 * 255.0), sxy = (double)t.xy[c] / 255.0;
        double det = s1 * sxx - sx * sx;
        if (s1 < 100.0 || det <= 1e-9 * s1 * s1)
            continue; /* too few, or one albedo only: the mean stands */
        double slope = (s1 * sxy - sx * sy) / det;
        slope = slope > 0.0 ? slope : 0.0; /* light is never taken away */
        f->ca_slope[k][c] = slope;
        f->ca_channel[k][c] = (sy - slope * sx) / s1;
    }
}

int colour_compute(const struct colour_params *prm, const struct hal_thread *threads,
                   const struct scan_calib *c, const struct decode_maps *m,
                   const struct tri_range *r, const uint8_t *white, const uint8_t *const *lights,
                   uint8_t *albedo, float *confidence, struct reflect_pool *pool)
{
    static struct frame_ctx f; /* static: the firmware keeps large state off the stack */
    static struct colour_layout lay;
    colour_layout(prm, c->light_count, &lay);
    memset(&f, 0, sizeof(f));
    f.prm = prm;
    f.ke_whole = whole_power(prm->ke);
    f.ko_whole = whole_power(prm->ko);
    f.lay = &lay;
    f.frames = lights;
    f.albedo = albedo;
    for (uint32_t k = 0; k < lay.count; k++) {
        if (lights[k] == NULL && colour_needs_frame(prm, &lay, k))
            return -EINVAL;
        if (lights[k] != NULL && lay.dark_of[k] == k)
            channel_offset(threads, m, lights[k], f.ca_channel[k]);
    }
    frame_tables(&f);
    int two = prm->method != COLOUR_NONE && prm->ca == COLOUR_CA_ALBEDO;
    compute_pass(&f, threads, c, m, r, white, albedo, confidence, pool, 0, !two);
    if (!two)
        return 0;
    for (uint32_t k = 0; k < lay.count; k++)
        if (lights[k] != NULL && lay.dark_of[k] == k)
            fit_ambient(&f, threads, m, albedo, confidence, k);
    frame_tables(&f);
    compute_pass(&f, threads, c, m, r, white, albedo, confidence, pool, 1, 1);
    return 0;
}
