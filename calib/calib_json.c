/* scanner calibrate --json: what a calibration found as one JSON object (docs/calibration.md). */
#include "calib_priv.h"
#include "job.h"

#include <stdio.h>

/* "name":[a,b,...] of @p n numbers (@p digits significant), a comma before unless @p first */
static void numbers(FILE *out, const char *name, const double *v, int n, int digits, int first)
{
    fprintf(out, "%s\"%s\":[", first ? "" : ",", name);
    for (int i = 0; i < n; i++)
        fprintf(out, "%s%.*g", i ? "," : "", digits, v[i]);
    fputc(']', out);
}

/* A lens: its focal lengths, principal point and distortion, and their sigmas (@p sd, 9). */
static void lens(FILE *out, const char *name, const double fc[4], const double dist[5],
                 const double *sd)
{
    fprintf(out, ",\"%s\":{\"fx_px\":%.9g,\"fy_px\":%.9g,\"cx_px\":%.9g,\"cy_px\":%.9g", name,
            fc[0], fc[1], fc[2], fc[3]);
    numbers(out, "distortion", dist, 5, 9, 0);
    if (sd != NULL) {
        fprintf(out, ",\"sigma\":{\"fx_px\":%.4g,\"fy_px\":%.4g,\"cx_px\":%.4g,\"cy_px\":%.4g",
                sd[0], sd[1], sd[2], sd[3]);
        numbers(out, "distortion", sd + 4, 5, 4, 0);
        fputc('}', out);
    }
    fputc('}', out);
}

void calib_json_write(FILE *out, const struct calib_result *r)
{
    const struct scan_calib *c = r->calib;
    fputs("{\"event\":\"calibration\",\"written\":", out);
    fputs(r->file != NULL ? "true" : "false", out);
    if (r->file == NULL) {
        fputs(",\"refused\":", out);
        job_json_string(out, r->refusal != NULL ? r->refusal : "");
        fputs("}\n", out);
        return;
    }
    fputs(",\"file\":", out);
    job_json_string(out, r->file);
    fputs(",\"report\":", out);
    job_json_string(out, r->report);
    fprintf(out, ",\"boards\":%u,\"camera_rms_px\":%.4g", (unsigned)r->boards, r->camera_rms_px);
    const double cam[4] = {c->cam_fx_px, c->cam_fy_px, c->cam_cx_px, c->cam_cy_px};
    lens(out, "camera", cam, c->cam_dist, r->have_sigma ? r->sigma->cam : NULL);
    if (!r->camera_only) {
        const double proj[4] = {c->proj_fx_px, c->proj_fy_px, c->proj_cx_px, c->proj_cy_px};
        fprintf(out, ",\"projector_rms_px\":%.4g", r->projector_rms_px);
        lens(out, "projector", proj, c->proj_dist, r->have_sigma ? r->sigma->proj : NULL);
        fputs(",\"pose\":{", out);
        numbers(out, "rotation", c->proj_rot, 9, 9, 1);
        numbers(out, "translation_mm", c->proj_trans_mm, 3, 9, 0);
        if (r->have_sigma) {
            fputs(",\"sigma\":{", out);
            numbers(out, "rotation_deg", r->sigma->rot_deg, 3, 4, 1);
            numbers(out, "translation_mm", r->sigma->trans_mm, 3, 4, 0);
            fputc('}', out);
        }
        fputs("},\"axis\":{", out);
        numbers(out, "point_mm", c->axis_point_mm, 3, 9, 1);
        numbers(out, "dir", c->axis_dir, 3, 9, 0);
        if (r->axis_dir_sigma_deg > 0.0)
            fprintf(out, ",\"sigma\":{\"dir_deg\":%.4g,\"across_mm\":%.4g,\"along_mm\":%.4g}",
                    r->axis_dir_sigma_deg, r->axis_across_sigma_mm, r->axis_along_sigma_mm);
        fputs("},\"lights\":[", out);
        for (uint32_t li = 0; li < c->light_count; li++) {
            fprintf(out, "%s{", li ? "," : "");
            numbers(out, "position_mm", c->light_pos_mm[li], 3, 9, 1);
            fprintf(out, ",\"gain\":%.6g", c->light_gain[li]);
            if (r->light_sigma_mm[li] > 0.0)
                fprintf(out, ",\"sigma_mm\":%.4g", r->light_sigma_mm[li]);
            fputc('}', out);
        }
        fputc(']', out);
    }
    if (r->depth_edge_mm > 0.0)
        fprintf(out,
                ",\"predicted\":{\"depth_centre_mm\":%.4g,\"depth_edge_mm\":%.4g,"
                "\"length_100_mm\":%.4g}",
                r->depth_centre_mm, r->depth_edge_mm, r->length_100_mm);
    fputs(",\"views\":[", out);
    for (uint32_t i = 0; i < r->residual_views; i++) {
        fprintf(out, "%s{\"view\":%u,\"camera_rms_px\":%.4g", i ? "," : "",
                (unsigned)r->residual_view[i], r->residual_camera_px[i]);
        if (r->residual_projector_px[i] >= 0.0)
            fprintf(out, ",\"projector_rms_px\":%.4g", r->residual_projector_px[i]);
        fputc('}', out);
    }
    fputc(']', out);
    fprintf(out, ",\"weak\":%s", r->weak[0] ? "true" : "false");
    if (r->weak[0]) {
        fputs(",\"weak_values\":", out);
        job_json_string(out, r->weak);
        fputs(",\"advice\":", out);
        job_json_string(out, r->advice);
        fputs(",\"add_placements\":", out);
        job_json_string(out, r->add_placements);
    }
    fputs("}\n", out);
}
