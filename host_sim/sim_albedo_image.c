/* The simulator's photographic paint ([sim] albedo_pattern = image): a PNG wrapped round the
 * object about the turntable's axis, its columns the azimuth (once round), its rows the height
 * (top row at the top), each pixel's sRGB decoded to a linear albedo. Loaded once per path. */
#include "sim_rig.h"

#include <errno.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SIM_IMAGE_MAX_SIDE 8192u
#define SIM_IMAGE_ALBEDO_MAX 0.9 /* white in the photo: a white paint, not a perfect reflector */

static struct {
    char path[HAL_MAX_PATH * 2 + 2];
    uint32_t width, height;
    float *linear; /* albedo, 3 per pixel */
} image;

static double srgb_decode(double e)
{
    return e <= 0.04045 ? e / 12.92 : pow((e + 0.055) / 1.055, 2.4);
}

int sim_albedo_image_load(const struct sim_config *cfg, const char *dir, char *err, size_t len)
{
    if (strcmp(cfg->albedo_pattern, "image") != 0)
        return 0;
    char path[sizeof(image.path)];
    const char *name = cfg->albedo_image;
    int n = name[0] == '/' ? snprintf(path, sizeof(path), "%s", name)
                           : snprintf(path, sizeof(path), "%s/%s", dir, name);
    if (name[0] == '\0' || n < 0 || (size_t)n >= sizeof(path)) {
        snprintf(err, len, "[sim] albedo_image: %s", name[0] ? "path too long" : "not given");
        return -EINVAL;
    }
    if (image.linear != NULL && strcmp(image.path, path) == 0)
        return 0;
    png_image png;
    memset(&png, 0, sizeof(png));
    png.version = PNG_IMAGE_VERSION;
    uint8_t *rgb = NULL;
    int ok = png_image_begin_read_from_file(&png, path);
    if (ok && (png.width > SIM_IMAGE_MAX_SIDE || png.height > SIM_IMAGE_MAX_SIDE)) {
        png_image_free(&png);
        snprintf(err, len, "[sim] albedo_image: %s: larger than %u pixels a side", path,
                 SIM_IMAGE_MAX_SIDE);
        return -EINVAL;
    }
    if (ok) {
        png.format = PNG_FORMAT_RGB;
        rgb = malloc(PNG_IMAGE_SIZE(png));
        ok = rgb != NULL && png_image_finish_read(&png, NULL, rgb, 0, NULL);
    }
    float *linear = ok ? malloc((size_t)png.width * png.height * 3 * sizeof(float)) : NULL;
    if (linear == NULL) {
        snprintf(err, len, "[sim] albedo_image: %s: %s", path,
                 png.message[0] ? png.message : "out of memory");
        png_image_free(&png);
        free(rgb);
        return -EINVAL;
    }
    for (size_t i = 0; i < (size_t)png.width * png.height * 3; i++)
        linear[i] = (float)(SIM_IMAGE_ALBEDO_MAX * srgb_decode(rgb[i] / 255.0));
    free(rgb);
    free(image.linear);
    image.linear = linear;
    image.width = png.width;
    image.height = png.height;
    snprintf(image.path, sizeof(image.path), "%s", path);
    return 0;
}

void sim_albedo_image_at(double u, double v, double albedo[3])
{
    if (image.linear == NULL) { /* not loaded: grey, which no measure mistakes for the photo */
        albedo[0] = albedo[1] = albedo[2] = 0.5;
        return;
    }
    /* pixel centres at +0.5; round the object in u, clamped at the top and bottom in v */
    double x = u * image.width - 0.5, y = v * image.height - 0.5;
    double fx = x - floor(x), fy = y - floor(y);
    long x0 = (long)floor(x), y0 = (long)floor(y);
    albedo[0] = albedo[1] = albedo[2] = 0.0;
    for (int q = 0; q < 4; q++) {
        long xs = ((x0 + q % 2) % (long)image.width + (long)image.width) % (long)image.width;
        long ys = y0 + q / 2;
        ys = ys < 0 ? 0 : ys >= (long)image.height ? (long)image.height - 1 : ys;
        double w = (q % 2 ? fx : 1.0 - fx) * (q / 2 ? fy : 1.0 - fy);
        const float *px = &image.linear[3 * ((size_t)ys * image.width + (size_t)xs)];
        for (int k = 0; k < 3; k++)
            albedo[k] += w * px[k];
    }
}
