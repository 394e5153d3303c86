/* The simulator's photographic paint ([sim] albedo_pattern = image): a picture wrapped round the
 * object about the turntable's axis, its columns the azimuth (once round), its rows the height
 * (top row at the top), each pixel's sRGB decoded to a linear albedo. The board reads the file
 * (board_albedo.c, through the project's PNG reader) and hands its pixels here. */
#include "sim_rig.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

int sim_albedo_image_set(const char *path, const uint8_t *rgb, uint32_t width, uint32_t height)
{
    float *linear =
        width > 0 && height > 0 ? malloc((size_t)width * height * 3 * sizeof(float)) : NULL;
    if (linear == NULL)
        return -ENOMEM;
    for (size_t i = 0; i < (size_t)width * height * 3; i++)
        linear[i] = (float)(SIM_IMAGE_ALBEDO_MAX * srgb_decode(rgb[i] / 255.0));
    free(image.linear);
    image.linear = linear;
    image.width = width;
    image.height = height;
    snprintf(image.path, sizeof(image.path), "%s", path);
    return 0;
}

int sim_albedo_image_is(const char *path)
{
    return image.linear != NULL && strcmp(image.path, path) == 0;
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
