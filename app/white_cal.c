/* White reference from one view of a white target: median of each method's compensated colour. */
#include "white_cal.h"

#include "scan.h"

#include <errno.h>
#include <string.h>

#define HALF 0.5

/* Median of a channel over the confident pixels (histogram: values are bytes). */
static int channel_median(const uint8_t *rgb, const float *conf, size_t n, int ch, uint32_t *count)
{
    uint32_t hist[256] = {0}, total = 0;
    for (size_t i = 0; i < n; i++)
        if (conf[i] > 0.5f) {
            hist[rgb[3 * i + (size_t)ch]]++;
            total++;
        }
    *count = total;
    uint32_t seen = 0;
    for (int v = 0; v < 256; v++) {
        seen += hist[v];
        if (total > 0 && seen * 2 >= total)
            return v;
    }
    return -1;
}

int white_cal_from_view(const struct app_config *cfg, const struct scan_calib *calib,
                        struct scan_view *view, double target_albedo, struct white_cal *out)
{
    memset(out, 0, sizeof(*out));
    size_t n = (size_t)cfg->camera.width * cfg->camera.height;
    for (uint32_t m = COLOUR_NONE; m <= COLOUR_MULTI; m++) {
        struct colour_params p = cfg->scan.colour;
        p.method = m;
        /* with this scale the stored byte is half the compensated value in grey levels: colour
         * frames at a shorter exposure are scaled up to the camera's, beyond 255 */
        p.white_scale[0] = p.white_scale[1] = p.white_scale[2] = HALF / 255.0;
        int rc = scan_recolour(&p, NULL, calib, view, NULL); /* none .. multi */
        if (rc != 0)
            return rc;
        for (int ch = 0; ch < 3; ch++) {
            int med = channel_median(view->rgb, view->confidence, n, ch, &out->pixels[m]);
            if (med <= 0 || med >= 255)
                return -EINVAL; /* nothing confident, or clipped: a dimmer exposure is needed */
            out->scale[m][ch] = target_albedo * HALF / med;
        }
    }
    return 0;
}
