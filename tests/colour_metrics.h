/* Colour differences for measuring albedo: linear RGB (sRGB primaries, D65) to CIELAB, CIEDE2000.
 */
#ifndef COLOUR_METRICS_H
#define COLOUR_METRICS_H

/** Linear RGB in 0..1 (sRGB primaries) to CIELAB (D65 white). */
void colour_linear_rgb_to_lab(const double rgb[3], double lab[3]);

/** CIEDE2000 colour difference (Sharma, Wu and Dalal 2005), kL = kC = kH = 1. */
double colour_ciede2000(const double lab1[3], const double lab2[3]);

#endif
