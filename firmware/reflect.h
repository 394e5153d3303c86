/* Reflectance parameters ([colour] method = fit; Park & DeSouza, section 6.5): per surface point
 * a diffuse colour, per material cluster a specular lobe, fitted from every light x view
 * observation, so that the model can be shown under any light. The model, in the units of the
 * multi method (a light's signal with Ca, falloff and the light's gain taken out, white-
 * referenced: rho cos(theta_i) for a matte surface), is a diffuse term and a microfacet lobe
 * with the GGX (Trowbridge-Reitz) distribution, scaled to 1 at its peak:
 *     S_l = rho cos(theta_l) + K D(alpha_l) / cos(theta_r),
 *     D(alpha) = a^4 / (cos^4(alpha) (a^2 + tan^2(alpha))^2)
 * alpha_l: the angle between the normal and the half vector of light l and the camera; theta_r:
 * between the normal and the camera; K: the specular colour x strength (RGB: a metal tints its
 * highlights); a: the roughness (GGX's alpha). GGX rather than the Gaussian of the simplified
 * Torrance-Sparrow model (Sato and Ikeuchi, 1994): measured materials have long tails (make
 * eval's gold metallic paint: dE00 2.87 with the Gaussian, 1.77 with GGX), and glTF's
 * metallic-roughness material is GGX, so mesh.glb takes the lobe as it is.
 *
 * Clusters as Lensch et al. (2003) begin them: k-means on the points' diffuse colour (from the
 * multi method, highlights already left out; clusters of one paint merged), then one lobe
 * fitted per cluster together with every sample's diffuse colour (least squares with the
 * diffuse colours projected out; the roughness by a search over a grid). The samples are a
 * fixed pool: each view gives up to REFLECT_MAX_SAMPLES / views of its valid pixels, evenly
 * spread.
 *
 * Then each cluster's lobe shape is measured: D at REFLECT_LOBE_NODES half-angles (piecewise
 * linear between them, 0 beyond REFLECT_LOBE_MAX_RAD, 1 at alpha = 0), starting from the GGX
 * fit, again with the diffuse colours free (least squares with a little smoothness between
 * neighbouring nodes, not below 0), so that a material whose tails are not GGX's (the haze of
 * a metallic paint) leaves no light on the diffuse colour. The colours and the relit
 * model use the measured shape (reflect_specular); the GGX lobe stays the cluster's summary
 * (reflectance.ini, the reflectance line) and is what mesh.glb's material takes.
 *
 * A cluster left without a lobe (matte) may have a diffuse that departs from Lambert's law as
 * Burley's does (brighter toward grazing light and view: Blender's Principled BSDF, many matte
 * paints): rho cos(theta_l) is then reflect_diffuse's basis, its roughness fitted per cluster
 * where it takes a share of the error (reflect.c's fit_retro). */
#ifndef REFLECT_H
#define REFLECT_H

#include "hal.h"

/** One sample: a pixel of a view with each light's signal and the angles that go with it. */
struct reflect_obs {
    float rho0[3];                   /**< the multi method's diffuse colour there */
    float cos_r;                     /**< cos of the angle between normal and camera */
    uint32_t lights;                 /**< mask: lights observed (lit, not saturated) */
    float signal[HAL_MAX_LIGHTS][3]; /**< S_l */
    float cos_i[HAL_MAX_LIGHTS];     /**< cos(theta_l) */
    float alpha[HAL_MAX_LIGHTS];     /**< alpha_l, radians */
    float cos_d[HAL_MAX_LIGHTS];     /**< cos(theta_d): half the angle between light and camera */
};

/** Nodes of a cluster's measured lobe shape: at half-angles REFLECT_LOBE_MAX_RAD (k / (n-1))^2. */
#define REFLECT_LOBE_NODES 16u
#define REFLECT_LOBE_MAX_RAD 1.2

/** A material cluster's lobe and where it sits in diffuse colour. */
struct reflect_cluster {
    double centre[3];   /**< mean diffuse colour of its samples (linear) */
    double specular[3]; /**< K: specular colour x strength */
    double roughness;   /**< a, GGX's alpha */
    double retro;       /**< the diffuse's roughness (reflect_diffuse; 0: Lambert's law) */
    double lobe[REFLECT_LOBE_NODES]; /**< the lobe's shape as measured (1 at alpha = 0) */
    double lobe_specular[3];         /**< K of the measured shape */
    int measured;                    /**< lobe[] is fitted: reflect_specular uses it */
    uint32_t samples;                /**< samples it was fitted from */
    double rms;                      /**< fit residual, albedo units */
};

struct reflect_model {
    uint32_t count; /**< clusters */
    struct reflect_cluster cluster[REFLECT_MAX_CLUSTERS];
};

/** The pool of samples and the model fitted to it: its owner (the job, a test) keeps it, static
 *  (about REFLECT_MAX_SAMPLES x 200 bytes), and passes it to the colour of method fit and to
 *  the glTF writer; two pools are two independent fits. The fields are reflect.c's. */
struct reflect_pool {
    struct reflect_obs obs[REFLECT_MAX_SAMPLES];
    float rho[REFLECT_MAX_SAMPLES][3]; /**< each sample's diffuse colour as fitted */
    uint8_t cluster[REFLECT_MAX_SAMPLES];
    uint32_t used[REFLECT_MAX_SAMPLES]; /**< lights kept after the outliers are out */
    uint32_t count, per_view;
    int collecting, fitted;
    struct reflect_model model;
};

/** Empty @p pl and start collecting: each of @p views views may add its share. */
void reflect_begin(struct reflect_pool *pl, uint32_t views);

/** Forget the samples and the model (a new scan): colouring with fit gives the multi estimate. */
void reflect_forget(struct reflect_pool *pl);

/** Collecting (after reflect_begin, before reflect_fit)? */
int reflect_collecting(const struct reflect_pool *pl);

/** Every how many valid pixels a view of @p valid_pixels valid pixels gives a sample. */
uint32_t reflect_stride(const struct reflect_pool *pl, uint32_t valid_pixels);

/** Add one sample (dropped when the pool is full or not collecting). */
void reflect_add(struct reflect_pool *pl, const struct reflect_obs *obs);

/** Cluster the pool into at most @p clusters and fit each cluster's lobe; the model is kept
 *  for reflect_model() and collecting stops. @param out  the model
 *  @retval 0 @retval -ENODATA too few samples (fewer than 100) */
int reflect_fit(struct reflect_pool *pl, uint32_t clusters, struct reflect_model *out);

/** The fitted model, or NULL before reflect_fit (or after reflect_begin). */
const struct reflect_model *reflect_model(const struct reflect_pool *pl);

/** The cluster nearest to diffuse colour @p rho (linear). */
uint32_t reflect_cluster_of(const struct reflect_model *m, const double rho[3]);

/** Cluster @p cl's specular part at @p alpha, @p cos_r: K D / cos(theta_r) per channel, with its
 *  measured shape (or its GGX lobe before that is fitted). */
void reflect_specular(const struct reflect_cluster *cl, double alpha, double cos_r, double out[3]);

/** Cluster @p cl's diffuse basis, what rho multiplies: Lambert's cos(theta_i) where cl->retro
 *  is 0, else Burley's diffuse of roughness r = cl->retro (as Blender's Principled BSDF has it),
 *      cos(theta_i) (1 + k F(cos theta_i)) (1 + k F(cos theta_r)),
 *      k = F_D90 - 1 = 2 r cos^2(theta_d) - 0.5,  F(c) = (1 - c)^5
 *  theta_d: the angle between the light and the half vector (@p cos_d). */
double reflect_diffuse(const struct reflect_cluster *cl, double cos_i, double cos_r, double cos_d);

/** cos(theta_d) from @p l_dot_v, the cosine between the unit directions to the light and to the
 *  camera: cos(2 theta_d) = L . V, so cos(theta_d) = sqrt((1 + L . V) / 2). */
double reflect_cos_d(double l_dot_v);

/** The lobe's factor D(alpha) / cos(theta_r) (times K: the specular part), D as above. */
double reflect_lobe(double roughness, double alpha, double cos_r);

#endif
