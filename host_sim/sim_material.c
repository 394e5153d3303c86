/* Material models of the simulated object; equations in docs/equations.md. */
#define _POSIX_C_SOURCE 200809L
#include "sim_material.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

int sim_material_load_abc(struct sim_material *mat, const char *csv_path, const char *name)
{
    FILE *f = fopen(csv_path, "r");
    if (f == NULL)
        return -errno;
    char line[512];
    int rc = -ESRCH; /* not -ENOENT: that would read as a missing file */
    while (fgets(line, sizeof(line), f) != NULL) {
        char row_name[64];
        double v[10];
        if (sscanf(line, "%63[^,],%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", row_name, &v[0], &v[1],
                   &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8]) != 10 ||
            strcmp(row_name, name) != 0)
            continue;
        memset(mat, 0, sizeof(*mat));
        mat->kind = SIM_MAT_ABC;
        snprintf(mat->name, sizeof(mat->name), "%s", name);
        for (int c = 0; c < 3; c++) {
            mat->abc_kd[c] = v[c];
            mat->abc_a[c] = v[3 + c];
        }
        mat->abc_b = v[6];
        mat->abc_c = v[7];
        mat->ior = v[8];
        rc = 0;
        break;
    }
    fclose(f);
    return rc;
}

/* Unpolarised Fresnel reflectance of a dielectric (Cook-Torrance form). */
static double fresnel(double cos_ih, double ior)
{
    double c = cos_ih, g2 = ior * ior - 1.0 + c * c;
    if (g2 < 0.0)
        return 1.0;
    double g = sqrt(g2);
    double a = (g - c) / (g + c), b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    return 0.5 * a * a * (1.0 + b * b);
}

void sim_material_eval(const struct sim_material *mat, const double albedo[3], vec3 n, vec3 l,
                       vec3 v, double rho[3])
{
    double cos_i = v3_dot(n, l), cos_o = v3_dot(n, v);
    for (int c = 0; c < 3; c++)
        rho[c] = 0.0;
    if (cos_i <= 0.0 || cos_o <= 0.0)
        return;
    for (int c = 0; c < 3; c++)
        rho[c] = albedo[c] * cos_i; /* Lambert: pi * (kd / pi) * cos(theta_i) */
    if (mat->kind == SIM_MAT_BURLEY) {
        /* Cycles' principled_diffuse (Burley 2015's split form: a Lambertian part darkened at
         * grazing, plus the retro-reflection RR ...): f = (1 - FL / 2) (1 - FV / 2) + RR (FL + FV
         * + FL FV (RR - 1)), RR = 2 roughness (L . H)^2, F* Schlick's (1 - cos)^5; rho = albedo f
         * cos(theta_i) */
        double fl = pow(1.0 - cos_i, 5.0), fv = pow(1.0 - cos_o, 5.0);
        double lh = v3_dot(l, v3_norm(v3_add(l, v))), rr = 2.0 * mat->roughness * lh * lh;
        double f = (1.0 - 0.5 * fl) * (1.0 - 0.5 * fv) + rr * (fl + fv + fl * fv * (rr - 1.0));
        for (int c = 0; c < 3; c++)
            rho[c] *= f;
    } else if (mat->kind == SIM_MAT_PHONG) {
        /* Jost et al. eq. 2: ks (cos alpha)^ke, alpha between the mirror direction and V. */
        vec3 r = v3_sub(v3_scale(n, 2.0 * cos_i), l);
        double cos_a = v3_dot(r, v);
        double spec = cos_a > 0.0 ? mat->ks * pow(cos_a, mat->ke) : 0.0;
        for (int c = 0; c < 3; c++)
            rho[c] += spec;
    } else if (mat->kind == SIM_MAT_ABC) {
        /* pi f cos_i with f_spec = F D G / (pi cos_i cos_o): the pi and cos_i cancel. */
        vec3 h = v3_norm(v3_add(l, v));
        double nh = v3_dot(n, h), ih = v3_dot(l, h);
        if (nh <= 0.0 || ih <= 0.0)
            return;
        double g = fmin(1.0, fmin(2.0 * nh * cos_i / ih, 2.0 * nh * cos_o / ih));
        double fg = fresnel(ih, mat->ior) * g / cos_o;
        for (int c = 0; c < 3; c++)
            rho[c] += fg * mat->abc_a[c] / pow(1.0 + mat->abc_b * (1.0 - nh), mat->abc_c);
    }
}
