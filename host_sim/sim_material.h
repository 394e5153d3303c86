/* Reflectance of the simulated object: Lambert, Phong (Jost et al. eq. 2), measured MERL
 * materials fitted to the ABC microfacet model (Low et al. 2012) and Burley's diffuse (the
 * Disney BRDF's, as Blender's Principled BSDF renders a matte paint). */
#ifndef SIM_MATERIAL_H
#define SIM_MATERIAL_H

#include "vec3.h"

enum sim_material_kind { SIM_MAT_LAMBERT, SIM_MAT_PHONG, SIM_MAT_ABC, SIM_MAT_BURLEY };

struct sim_material {
    enum sim_material_kind kind;
    double ks, ke;       /**< Phong specular strength and shininess */
    double abc_kd[3];    /**< ABC diffuse colour from the table */
    double abc_a[3];     /**< ABC lobe height per channel */
    double abc_b, abc_c; /**< ABC lobe shape */
    double ior;          /**< index of refraction for the Fresnel term */
    double roughness;    /**< Burley's diffuse roughness */
    char name[64];
};

/** Load material @p name from the MERL/ABC table (CSV: name,kd_r,kd_g,kd_b,A_r,A_g,A_b,B,C,ior).
 *  @retval 0 ok @retval -ESRCH no such material in the table @retval -errno the file (-ENOENT:
 * missing) */
int sim_material_load_abc(struct sim_material *mat, const char *csv_path, const char *name);

/** Reflected fraction per channel, as camera counts per unit source irradiance at normal incidence:
 *  rho = pi * f(i, o) * cos(theta_i). For Lambert rho = albedo * cos(theta_i).
 *  @param albedo  diffuse colour at the point (the painted pattern)
 *  @param n, l, v unit normal, direction to the source, direction to the camera */
void sim_material_eval(const struct sim_material *mat, const double albedo[3], vec3 n, vec3 l,
                       vec3 v, double rho[3]);

#endif
