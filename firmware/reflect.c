/* Reflectance parameters: a pool of light x view observations (the caller's struct
 * reflect_pool), k-means clusters on the diffuse
 * colour, and per cluster a GGX lobe (reflect.h). */
#include "reflect.h"

#include "lsq.h"

#include <errno.h>
#include <stddef.h>
#include <math.h>
#include <string.h>

/* The pool's state and model; not its samples (each is written before it is read). */
static void clear(struct reflect_pool *pl)
{
    memset(&pl->count, 0, sizeof(*pl) - offsetof(struct reflect_pool, count));
}

void reflect_begin(struct reflect_pool *pl, uint32_t views)
{
    clear(pl);
    pl->per_view = REFLECT_MAX_SAMPLES / (views > 0 ? views : 1);
    pl->collecting = 1;
}

void reflect_forget(struct reflect_pool *pl)
{
    clear(pl);
}

int reflect_collecting(const struct reflect_pool *pl)
{
    return pl->collecting;
}

uint32_t reflect_stride(const struct reflect_pool *pl, uint32_t valid_pixels)
{
    return pl->per_view == 0 ? UINT32_MAX : valid_pixels / pl->per_view + 1;
}

void reflect_add(struct reflect_pool *pl, const struct reflect_obs *obs)
{
    if (pl->collecting && pl->count < REFLECT_MAX_SAMPLES)
        pl->obs[pl->count++] = *obs;
}

const struct reflect_model *reflect_model(const struct reflect_pool *pl)
{
    return pl->fitted ? &pl->model : NULL;
}

double reflect_lobe(double roughness, double alpha, double cos_r)
{
    double a2 = roughness * roughness, c = cos(alpha), t2 = (1.0 - c * c) / (c * c);
    return a2 * a2 / (c * c * c * c * (a2 + t2) * (a2 + t2)) / (cos_r > 0.05 ? cos_r : 0.05);
}

/* Schlick's (1 - c)^5, the shape of Burley's grazing term */
static double schlick(double c)
{
    double x = 1.0 - (c < 0.0 ? 0.0 : c > 1.0 ? 1.0 : c), x2 = x * x;
    return x2 * x2 * x;
}

double reflect_diffuse(const struct reflect_cluster *cl, double cos_i, double cos_r, double cos_d)
{
    if (cl->retro == 0.0)
        return cos_i;
    double k = 2.0 * cl->retro * cos_d * cos_d - 0.5;
    return cos_i * (1.0 + k * schlick(cos_i)) * (1.0 + k * schlick(cos_r));
}

double reflect_cos_d(double l_dot_v)
{
    return sqrt(l_dot_v > -1.0 ? 0.5 * (1.0 + l_dot_v) : 0.0);
}

static double node_angle(uint32_t k)
{
    double t = (double)k / (REFLECT_LOBE_NODES - 1);
    return REFLECT_LOBE_MAX_RAD * t * t;
}

/* The two nodes around @p alpha and the second's weight; @retval 0 beyond the last node */
static int lobe_segment(double alpha, uint32_t *k0, double *t)
{
    if (!(alpha >= 0.0) || alpha >= REFLECT_LOBE_MAX_RAD)
        return 0;
    double u = sqrt(alpha / REFLECT_LOBE_MAX_RAD) * (REFLECT_LOBE_NODES - 1);
    *k0 = (uint32_t)u;
    if (*k0 >= REFLECT_LOBE_NODES - 1)
        *k0 = REFLECT_LOBE_NODES - 2;
    double a0 = node_angle(*k0), a1 = node_angle(*k0 + 1);
    *t = (alpha - a0) / (a1 - a0);
    return 1;
}

static double lobe_shape(const struct reflect_cluster *cl, double alpha, double cos_r)
{
    uint32_t k0;
    double t;
    if (!cl->measured)
        return reflect_lobe(cl->roughness, alpha, cos_r);
    if (!lobe_segment(alpha, &k0, &t))
        return 0.0;
    return ((1.0 - t) * cl->lobe[k0] + t * cl->lobe[k0 + 1]) / (cos_r > 0.05 ? cos_r : 0.05);
}

void reflect_specular(const struct reflect_cluster *cl, double alpha, double cos_r, double out[3])
{
    double g = lobe_shape(cl, alpha, cos_r);
    const double *k = cl->measured ? cl->lobe_specular : cl->specular;
    for (int ch = 0; ch < 3; ch++)
        out[ch] = k[ch] * g;
}

/* Colour feature for the clusters: square roots, roughly even steps of lightness. */
static double feature_dist2(const float a[3], const double centre[3])
{
    double d = 0.0;
    for (int c = 0; c < 3; c++) {
        double x = sqrt(a[c] > 0.0f ? a[c] : 0.0f) - sqrt(centre[c] > 0.0 ? centre[c] : 0.0);
        d += x * x;
    }
    return d;
}

uint32_t reflect_cluster_of(const struct reflect_model *m, const double rho[3])
{
    const float f[3] = {(float)rho[0], (float)rho[1], (float)rho[2]};
    uint32_t best = 0;
    for (uint32_t k = 1; k < m->count; k++)
        if (feature_dist2(f, m->cluster[k].centre) < feature_dist2(f, m->cluster[best].centre))
            best = k;
    return best;
}

static void kmeans_rounds(struct reflect_pool *pl, struct reflect_model *m, int rounds);

/* The least share of a cluster's error (its diffuse colours alone) a lobe must take to be kept
 * (reflect_fit). Measured (make eval-cycles' Lambertian bunny, make eval's owls): a surface
 * with no highlight at all 1.6-5.7% (a coloured "lobe" that fitted the grazing light and the
 * normals' noise, and darkened the colour: 2.02 -> 2.64 mean dE00 against multi), red plastic
 * 16-33%, gold metallic paint 71-92%. */
#define LOBE_MIN_SHARE 0.10

/* The broadest lobe kept (GGX roughness). A highlight's is far narrower (make eval's red plastic
 * 0.35-0.42, gold metallic paint 0.27-0.29); a broader one fits how a matte surface's light
 * departs from Lambert's law (Burley's retro-reflection in Blender's Principled BSDF: 0.84-0.92
 * on make eval-cycles' bunny, coloured like the paint), and taken off each light it darkened
 * that texture from multi's 2.29 mean dE00 to 3.53 (2.18 without it). */
#define LOBE_MAX_ROUGHNESS 0.7

/* Colours nearer than this (feature_dist2; 0.17 in square-root units) are one paint: make
 * eval's nearest two paints, green and blue, are 0.19 apart. */
#define SAME_PAINT 0.03

/* k-means on the multi method's colour: seeds by farthest point (deterministic), ten rounds. */
static uint32_t cluster_samples(struct reflect_pool *pl, uint32_t wanted, struct reflect_model *m)
{
    uint32_t k = 0;
    double mean[3] = {0, 0, 0}; /* the first seed: the mean colour (an outlier would pull the
                                   next seed into the bulk and split one paint in two) */
    for (uint32_t i = 0; i < pl->count; i++)
        for (int c = 0; c < 3; c++)
            mean[c] += pl->obs[i].rho0[c] / pl->count;
    memcpy(m->cluster[0].centre, mean, sizeof(mean));
    for (k = 1; k < wanted; k++) { /* the sample farthest from every seed so far */
        double far = 0.0;
        uint32_t at = 0;
        for (uint32_t i = 0; i < pl->count; i++) {
            double d = 1e30;
            for (uint32_t j = 0; j < k; j++)
                d = fmin(d, feature_dist2(pl->obs[i].rho0, m->cluster[j].centre));
            if (d > far)
                far = d, at = i;
        }
        if (far < SAME_PAINT) /* no other colour there: fewer clusters */
            break;
        for (int c = 0; c < 3; c++)
            m->cluster[k].centre[c] = pl->obs[at].rho0[c];
    }
    m->count = k;
    kmeans_rounds(pl, m, 10);
    /* a cluster of a few samples would fit its lobe to their noise: its samples join the
     * nearest cluster (they keep their own diffuse colour; only the lobe is shared) */
    uint32_t least = pl->count / 50 > 200 ? pl->count / 50 : 200;
    for (;;) {
        uint32_t small = 0;
        for (uint32_t c = 1; c < m->count; c++)
            if (m->cluster[c].samples < m->cluster[small].samples)
                small = c;
        if (m->count == 1 || m->cluster[small].samples >= least)
            break;
        m->cluster[small] = m->cluster[--m->count];
        kmeans_rounds(pl, m, 3);
    }
    /* one paint is one cluster: the multi colours of a single paint spread (what the weights
     * leave of the lobe, the noise), and a sample far out seeds a cluster of its own that then
     * takes half of the paint (make eval's uniform cans came out as two, one with a lobe fitted
     * to the samples the sheen brightened most): centres nearer than SAME_PAINT are merged (a
     * merged paint keeps its pixels' own diffuse colours; only the lobe is one). */
    for (;;) {
        uint32_t q = 1;
        double nearest = 1e30;
        for (uint32_t a = 0; a < m->count; a++)
            for (uint32_t b = a + 1; b < m->count; b++) {
                const float fa[3] = {(float)m->cluster[a].centre[0], (float)m->cluster[a].centre[1],
                                     (float)m->cluster[a].centre[2]};
                double d = feature_dist2(fa, m->cluster[b].centre);
                if (d < nearest)
                    nearest = d, q = b;
            }
        if (m->count < 2 || nearest >= SAME_PAINT)
            break;
        m->cluster[q] = m->cluster[--m->count];
        kmeans_rounds(pl, m, 3);
    }
    return m->count;
}

/* @p rounds of k-means over the pool from @p m's centres; each cluster's sample count. */
static void kmeans_rounds(struct reflect_pool *pl, struct reflect_model *m, int rounds)
{
    for (int round = 0; round < rounds; round++) {
        double sum[REFLECT_MAX_CLUSTERS][3] = {{0}};
        uint32_t n[REFLECT_MAX_CLUSTERS] = {0};
        for (uint32_t i = 0; i < pl->count; i++) {
            double rho[3] = {pl->obs[i].rho0[0], pl->obs[i].rho0[1], pl->obs[i].rho0[2]};
            uint32_t c = reflect_cluster_of(m, rho);
            pl->cluster[i] = (uint8_t)c;
            n[c]++;
            for (int ch = 0; ch < 3; ch++)
                sum[c][ch] += rho[ch];
        }
        for (uint32_t c = 0; c < m->count; c++)
            for (int ch = 0; ch < 3 && n[c] > 0; ch++)
                m->cluster[c].centre[ch] = sum[c][ch] / n[c];
        for (uint32_t c = 0; c < m->count; c++)
            m->cluster[c].samples = n[c];
    }
}

/* The diffuse colours and the lobe are fitted together: a sample's diffuse colour is free (rho
 * = its least squares over its lights), so what the lobe may explain there is what rho cos_l
 * cannot: each light's value less its share of the sample's cos-weighted mean (the projection
 * P = I - c c^T / c^T c, c the sample's cos_l). Fitting the lobe to the projected values is the
 * joint least squares (variable projection); alternating with fit_diffuse instead moves along
 * the valley where a lobe's slowly varying tail and the diffuse colour trade for each other only
 * a little each round, and the tail, most of the light on dark paint, came out half as high
 * (make eval's gold owl). @p c, @p v: the sample's cosines and one value per light, @p n
 * lights; @retval c^T v / c^T c, the amount of c to take from each v_l */
static double along_cos(const double *c, const double *v, uint32_t n)
{
    double cc = 0.0, cv = 0.0;
    for (uint32_t l = 0; l < n; l++)
        cc += c[l] * c[l], cv += c[l] * v[l];
    return cc > 0.0 ? cv / cc : 0.0;
}

/* Sample @p i's kept lights: their cosines, lobe angles and signals (@retval how many). */
static uint32_t kept_lights(struct reflect_pool *pl, uint32_t i, double cos_l[HAL_MAX_LIGHTS],
                            double alpha[HAL_MAX_LIGHTS], double sig[3][HAL_MAX_LIGHTS])
{
    const struct reflect_obs *o = &pl->obs[i];
    const struct reflect_cluster *cl = &pl->model.cluster[pl->cluster[i]];
    uint32_t n = 0;
    for (uint32_t l = 0; l < HAL_MAX_LIGHTS; l++) {
        if (!(pl->used[i] >> l & 1u))
            continue;
        cos_l[n] = reflect_diffuse(cl, o->cos_i[l], o->cos_r, o->cos_d[l]);
        alpha[n] = o->alpha[l];
        for (int ch = 0; ch < 3; ch++)
            sig[ch][n] = o->signal[l][ch];
        n++;
    }
    return n;
}

/* The lobe's K for the shape of @p shape (its GGX roughness, or its measured shape; NULL: no
 * lobe, K = 0) over cluster @p c's kept observations, the diffuse colours free (along_cos), per
 * channel, not below 0; @p no_lobe (may be NULL): the squared error of the diffuse colours
 * alone (K = 0). @retval the squared error */
static double fit_k(struct reflect_pool *pl, uint32_t c, const struct reflect_cluster *shape,
                    double k_out[3], double *no_lobe)
{
    double sgg = 0.0, srg[3] = {0, 0, 0}, srr = 0.0;
    for (uint32_t i = 0; i < pl->count; i++) {
        double cos_l[HAL_MAX_LIGHTS], alpha[HAL_MAX_LIGHTS], sig[3][HAL_MAX_LIGHTS];
        double g[HAL_MAX_LIGHTS];
        uint32_t n = pl->cluster[i] == c ? kept_lights(pl, i, cos_l, alpha, sig) : 0;
        if (n < 2) /* one light: its diffuse colour explains it all */
            continue;
        for (uint32_t l = 0; l < n; l++)
            g[l] = shape != NULL ? lobe_shape(shape, alpha[l], pl->obs[i].cos_r) : 0.0;
        double mg = along_cos(cos_l, g, n), ms[3];
        for (int ch = 0; ch < 3; ch++)
            ms[ch] = along_cos(cos_l, sig[ch], n);
        for (uint32_t l = 0; l < n; l++) {
            double gp = g[l] - mg * cos_l[l];
            sgg += gp * gp;
            for (int ch = 0; ch < 3; ch++) {
                double r = sig[ch][l] - ms[ch] * cos_l[l];
                srg[ch] += r * gp;
                srr += r * r;
            }
        }
    }
    double err = srr;
    if (no_lobe != NULL)
        *no_lobe = srr;
    for (int ch = 0; ch < 3; ch++) {
        k_out[ch] = sgg > 0.0 && srg[ch] > 0.0 ? srg[ch] / sgg : 0.0;
        err += k_out[ch] * k_out[ch] * sgg - 2.0 * k_out[ch] * srg[ch];
    }
    return err;
}

/* K for GGX of @p roughness; @p no_lobe as fit_k's. @retval the squared error */
static double fit_specular(struct reflect_pool *pl, uint32_t c, double roughness, double k_out[3],
                           double *no_lobe)
{
    struct reflect_cluster ggx;
    memset(&ggx, 0, sizeof(ggx));
    ggx.roughness = roughness;
    return fit_k(pl, c, &ggx, k_out, no_lobe);
}

/* Each sample's diffuse colour given its cluster's lobe, for judging outliers: least squares
 * over its kept lights, rho = sum (S_l - K g_l) cos_l / sum cos_l^2 (along_cos). */
static void fit_diffuse(struct reflect_pool *pl, const struct reflect_model *m)
{
    for (uint32_t i = 0; i < pl->count; i++) {
        double cos_l[HAL_MAX_LIGHTS], alpha[HAL_MAX_LIGHTS], sig[3][HAL_MAX_LIGHTS];
        uint32_t n = kept_lights(pl, i, cos_l, alpha, sig);
        for (uint32_t l = 0; l < n; l++) {
            double sp[3];
            reflect_specular(&m->cluster[pl->cluster[i]], alpha[l], pl->obs[i].cos_r, sp);
            for (int ch = 0; ch < 3; ch++)
                sig[ch][l] -= sp[ch];
        }
        for (int ch = 0; ch < 3; ch++)
            pl->rho[i][ch] =
                n > 0 ? (float)fmax(0.0, along_cos(cos_l, sig[ch], n)) : pl->obs[i].rho0[ch];
    }
}

/* Sample @p i's light @p l less the model of cluster @p cl (luminance). */
static double residual(struct reflect_pool *pl, const struct reflect_cluster *cl, uint32_t i,
                       uint32_t l)
{
    const struct reflect_obs *o = &pl->obs[i];
    double sp[3], r = 0.0;
    reflect_specular(cl, o->alpha[l], o->cos_r, sp);
    for (int ch = 0; ch < 3; ch++)
        r += (o->signal[l][ch] -
              pl->rho[i][ch] * reflect_diffuse(cl, o->cos_i[l], o->cos_r, o->cos_d[l]) - sp[ch]) /
             3.0;
    return r;
}

/* Observations far off the model (a shadow edge, a neighbour's paint, a wrong normal) are left
 * out: more than 4 x the cluster's median absolute residual (luminance), and at least 0.02. */
static void drop_outliers(struct reflect_pool *pl, const struct reflect_model *m)
{
    for (uint32_t c = 0; c < m->count; c++) {
        double hist[64] = {0}; /* |residual| in steps of 0.005: the median without a sort */
        uint32_t n = 0;
        const struct reflect_cluster *cl = &m->cluster[c];
        for (uint32_t i = 0; i < pl->count; i++) {
            if (pl->cluster[i] != c)
                continue;
            const struct reflect_obs *o = &pl->obs[i];
            for (uint32_t l = 0; l < HAL_MAX_LIGHTS; l++) {
                if (!(o->lights >> l & 1u))
                    continue;
                hist[(int)fmin(63.0, fabs(residual(pl, cl, i, l)) / 0.005)]++;
                n++;
            }
        }
        double median = 0.0, seen = 0.0;
        for (int b = 0; b < 64 && seen < n / 2.0; b++)
            seen += hist[b], median = (b + 0.5) * 0.005;
        double limit = fmax(0.02, 4.0 * median);
        for (uint32_t i = 0; i < pl->count; i++) {
            if (pl->cluster[i] != c)
                continue;
            const struct reflect_obs *o = &pl->obs[i];
            pl->used[i] = 0;
            for (uint32_t l = 0; l < HAL_MAX_LIGHTS; l++) {
                if (!(o->lights >> l & 1u))
                    continue;
                if (fabs(residual(pl, cl, i, l)) <= limit)
                    pl->used[i] |= 1u << l;
            }
        }
    }
}

/* Cluster @p c's roughness: the grid value with the least error, then a golden-section search
 * between its neighbours. @retval the share of the diffuse colours' own error the lobe takes */
static double fit_lobe(struct reflect_pool *pl, struct reflect_cluster *cl, uint32_t c)
{
    enum { GRID = 24 };
    double best_s = 0.1, best_e = 1e300, k[3];
    for (int g = 0; g < GRID; g++) { /* 0.02 .. 1 rad, evenly in log */
        double s = 0.02 * pow(50.0, g / (GRID - 1.0)), e = fit_specular(pl, c, s, k, NULL);
        if (e < best_e)
            best_e = e, best_s = s;
    }
    double step = pow(50.0, 1.0 / (GRID - 1.0)), lo = best_s / step, hi = best_s * step;
    const double phi = 0.6180339887498949;
    for (int it = 0; it < 20; it++) {
        double a = hi - phi * (hi - lo), b = lo + phi * (hi - lo);
        if (fit_specular(pl, c, a, k, NULL) < fit_specular(pl, c, b, k, NULL))
            hi = b;
        else
            lo = a;
    }
    cl->roughness = 0.5 * (lo + hi);
    double none, e = fit_specular(pl, c, cl->roughness, cl->specular, &none);
    uint32_t n = 0;
    for (uint32_t i = 0; i < pl->count; i++)
        for (uint32_t l = 0; pl->cluster[i] == c && l < HAL_MAX_LIGHTS; l++)
            n += pl->used[i] >> l & 1u;
    cl->rms = n > 0 ? sqrt(fmax(0.0, e) / (3.0 * n)) : 0.0;
    return none > 0.0 ? 1.0 - e / none : 0.0;
}

/* A matte cluster's diffuse roughness (reflect_diffuse): Burley's, by a golden-section search
 * over RETRO_MIN .. RETRO_MAX of the squared error of its diffuse colours alone (free:
 * along_cos), kept where it takes at least RETRO_MIN_SHARE of the error Lambert's law leaves.
 * Measured (make eval-cycles' bunny, four paints): on Cycles' frames (Blender's Principled
 * BSDF, roughness 1) 1.02-1.17 found, taking 23-50% of the error; on the simulator's own
 * (Lambert's law) 0.2-0.6% or none, so they stay Lambertian. */
#define RETRO_MIN 0.001
#define RETRO_MAX 1.5
#define RETRO_MIN_SHARE 0.05
static double retro_error(struct reflect_pool *pl, struct reflect_cluster *cl, uint32_t c,
                          double retro)
{
    double k[3];
    cl->retro = retro;
    return fit_k(pl, c, NULL, k, NULL); /* the diffuse colours alone, on cl's basis */
}

static void fit_retro(struct reflect_pool *pl, struct reflect_cluster *cl, uint32_t c)
{
    const double phi = 0.6180339887498949;
    double lo = RETRO_MIN, hi = RETRO_MAX, a = hi - phi * (hi - lo), b = lo + phi * (hi - lo);
    double ea = retro_error(pl, cl, c, a), eb = retro_error(pl, cl, c, b);
    for (int it = 0; it < 18; it++) { /* golden section: one new point a step */
        if (ea < eb) {
            hi = b, b = a, eb = ea;
            a = hi - phi * (hi - lo), ea = retro_error(pl, cl, c, a);
        } else {
            lo = a, a = b, ea = eb;
            b = lo + phi * (hi - lo), eb = retro_error(pl, cl, c, b);
        }
    }
    double best = ea < eb ? a : b, burley = ea < eb ? ea : eb;
    cl->retro = burley < (1.0 - RETRO_MIN_SHARE) * retro_error(pl, cl, c, 0.0) ? best : 0.0;
}

/* Cluster @p c's lobe shape at the nodes for its K (least squares over its kept observations,
 * the diffuse colours free (along_cos), a little smoothness between neighbours, not below 0, 1
 * at alpha = 0), then K for the shape. */
static void fit_measured(struct reflect_pool *pl, struct reflect_cluster *cl, uint32_t c)
{
    enum { N = REFLECT_LOBE_NODES };
    static double a[N * N], b[N], x[N], g[N][HAL_MAX_LIGHTS]; /* static: off the stack */
    memset(a, 0, sizeof(a));
    memset(b, 0, sizeof(b));
    const double *k = cl->lobe_specular;
    double kk = k[0] * k[0] + k[1] * k[1] + k[2] * k[2];
    for (uint32_t i = 0; i < pl->count; i++) {
        double cos_l[HAL_MAX_LIGHTS], alpha[HAL_MAX_LIGHTS], sig[3][HAL_MAX_LIGHTS];
        double s[HAL_MAX_LIGHTS];
        uint32_t n = pl->cluster[i] == c ? kept_lights(pl, i, cos_l, alpha, sig) : 0;
        if (n < 2)
            continue;
        double inv = 1.0 / (pl->obs[i].cos_r > 0.05 ? pl->obs[i].cos_r : 0.05), mg[N];
        memset(g, 0, sizeof(g));
        for (uint32_t l = 0; l < n; l++) { /* light l: the nodes around its alpha */
            uint32_t k0;
            double t;
            if (lobe_segment(alpha[l], &k0, &t))
                g[k0][l] = (1.0 - t) * inv, g[k0 + 1][l] = t * inv;
            s[l] = k[0] * sig[0][l] + k[1] * sig[1][l] + k[2] * sig[2][l];
        }
        for (uint32_t q = 0; q < N; q++)
            mg[q] = along_cos(cos_l, g[q], n);
        double ms = along_cos(cos_l, s, n);
        for (uint32_t l = 0; l < n; l++) {
            double gp[N], sp = s[l] - ms * cos_l[l];
            for (uint32_t q = 0; q < N; q++)
                gp[q] = g[q][l] - mg[q] * cos_l[l];
            for (uint32_t p = 0; p < N; p++) {
                b[p] += gp[p] * sp;
                for (uint32_t q = 0; q < N; q++)
                    a[p * N + q] += kk * gp[p] * gp[q];
            }
        }
    }
    double trace = 0.0;
    for (uint32_t n = 0; n < N; n++)
        trace += a[n * N + n];
    double lambda = 1e-3 * trace / N; /* smoothness: (x_n - x_n+1)^2 */
    for (uint32_t n = 0; n + 1 < N; n++) {
        a[n * N + n] += lambda, a[(n + 1) * N + n + 1] += lambda;
        a[n * N + n + 1] -= lambda, a[(n + 1) * N + n] -= lambda;
    }
    if (lsq_solve(N, a, b, x) != 0 || x[0] <= 0.0)
        return;
    for (uint32_t n = 0; n < N; n++)
        cl->lobe[n] = fmax(0.0, x[n] / x[0]);
    for (int ch = 0; ch < 3; ch++)
        cl->lobe_specular[ch] *= x[0];
    cl->measured = 1;
    fit_k(pl, c, cl, cl->lobe_specular, NULL); /* K for this shape */
}

int reflect_fit(struct reflect_pool *pl, uint32_t clusters, struct reflect_model *out)
{
    pl->collecting = 0;
    if (pl->count < 100)
        return -ENODATA;
    struct reflect_model *m = &pl->model;
    memset(m, 0, sizeof(*m));
    cluster_samples(pl,
                    clusters < 1                      ? 1
                    : clusters > REFLECT_MAX_CLUSTERS ? REFLECT_MAX_CLUSTERS
                                                      : clusters,
                    m);
    for (uint32_t i = 0; i < pl->count; i++)
        pl->used[i] = pl->obs[i].lights;
    for (uint32_t c = 0; c < m->count; c++)
        m->cluster[c].roughness = 0.1;
    /* the lobes (the diffuse colours free: along_cos); the outliers judged on that model and
     * its diffuse colours, twice (a first model leans towards them) */
    double share[REFLECT_MAX_CLUSTERS] = {0};
    for (int round = 0; round < 3; round++) {
        for (uint32_t c = 0; c < m->count; c++)
            share[c] = fit_lobe(pl, &m->cluster[c], c);
        if (round < 2) {
            fit_diffuse(pl, m);
            drop_outliers(pl, m);
        }
    }
    /* A cluster whose lobe takes less than LOBE_MIN_SHARE of the error its diffuse colours leave
     * alone, or whose lobe is broader than LOBE_MAX_ROUGHNESS, is matte (K = 0): what such a
     * lobe fits is the diffuse model's own misfit, not a highlight, and taking it off darkens
     * the colour; that misfit is then the diffuse's own roughness where it is Burley's */
    for (uint32_t c = 0; c < m->count; c++)
        if (share[c] < LOBE_MIN_SHARE || m->cluster[c].roughness > LOBE_MAX_ROUGHNESS) {
            share[c] = 0.0, memset(m->cluster[c].specular, 0, sizeof(m->cluster[c].specular));
            fit_retro(pl, &m->cluster[c], c);
        }
    /* then the lobe's shape as measured, from GGX's: real materials' tails are not GGX's, and
     * where the paint is dark the tails are most of the light (make eval's gold metallic
     * paint: dark paint dE00 12.45 with GGX, 9.83 measured; relit 3.18, 2.94) */
    for (uint32_t c = 0; c < m->count; c++) {
        struct reflect_cluster *cl = &m->cluster[c];
        for (uint32_t n = 0; n < REFLECT_LOBE_NODES; n++)
            cl->lobe[n] = reflect_lobe(cl->roughness, node_angle(n), 1.0);
        memcpy(cl->lobe_specular, cl->specular, sizeof(cl->lobe_specular));
    }
    for (int round = 0; round < 6; round++) /* K's colour and the shape settle together */
        for (uint32_t c = 0; c < m->count; c++)
            if (share[c] >= LOBE_MIN_SHARE)
                fit_measured(pl, &m->cluster[c], c);
    pl->fitted = 1;
    *out = *m;
    return 0;
}
