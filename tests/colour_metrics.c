/* CIELAB and CIEDE2000, following Sharma, Wu and Dalal (2005), including its notes on hue angles.
 */
#include "colour_metrics.h"

#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double lab_f(double t)
{
    const double d = 6.0 / 29.0;
    return t > d * d * d ? cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
}

void colour_linear_rgb_to_lab(const double rgb[3], double lab[3])
{
    /* sRGB primaries, D65 (IEC 61966-2-1) */
    double x = 0.4124564 * rgb[0] + 0.3575761 * rgb[1] + 0.1804375 * rgb[2];
    double y = 0.2126729 * rgb[0] + 0.7151522 * rgb[1] + 0.0721750 * rgb[2];
    double z = 0.0193339 * rgb[0] + 0.1191920 * rgb[1] + 0.9503041 * rgb[2];
    double fx = lab_f(x / 0.95047), fy = lab_f(y / 1.0), fz = lab_f(z / 1.08883);
    lab[0] = 116.0 * fy - 16.0;
    lab[1] = 500.0 * (fx - fy);
    lab[2] = 200.0 * (fy - fz);
}

static double deg(double rad)
{
    return rad * 180.0 / M_PI;
}

static double rad(double d)
{
    return d * M_PI / 180.0;
}

static double hue_deg(double b, double a)
{
    if (a == 0.0 && b == 0.0)
        return 0.0;
    double h = deg(atan2(b, a));
    return h < 0.0 ? h + 360.0 : h;
}

double colour_ciede2000(const double lab1[3], const double lab2[3])
{
    double l1 = lab1[0], a1 = lab1[1], b1 = lab1[2], l2 = lab2[0], a2 = lab2[1], b2 = lab2[2];
    double c1 = hypot(a1, b1), c2 = hypot(a2, b2), cbar = 0.5 * (c1 + c2);
    double c7 = pow(cbar, 7.0);
    double g = 0.5 * (1.0 - sqrt(c7 / (c7 + pow(25.0, 7.0))));
    double a1p = (1.0 + g) * a1, a2p = (1.0 + g) * a2;
    double c1p = hypot(a1p, b1), c2p = hypot(a2p, b2);
    double h1p = hue_deg(b1, a1p), h2p = hue_deg(b2, a2p);
    double dlp = l2 - l1, dcp = c2p - c1p, dhp = 0.0;
    if (c1p * c2p != 0.0) {
        dhp = h2p - h1p;
        if (dhp > 180.0)
            dhp -= 360.0;
        else if (dhp < -180.0)
            dhp += 360.0;
    }
    double dHp = 2.0 * sqrt(c1p * c2p) * sin(rad(dhp) / 2.0);
    double lbarp = 0.5 * (l1 + l2), cbarp = 0.5 * (c1p + c2p), hbarp = h1p + h2p;
    if (c1p * c2p != 0.0) {
        if (fabs(h1p - h2p) <= 180.0)
            hbarp *= 0.5;
        else
            hbarp = h1p + h2p < 360.0 ? 0.5 * (hbarp + 360.0) : 0.5 * (hbarp - 360.0);
    }
    double t = 1.0 - 0.17 * cos(rad(hbarp - 30.0)) + 0.24 * cos(rad(2.0 * hbarp)) +
               0.32 * cos(rad(3.0 * hbarp + 6.0)) - 0.20 * cos(rad(4.0 * hbarp - 63.0));
    double dtheta = 30.0 * exp(-pow((hbarp - 275.0) / 25.0, 2.0));
    double cbarp7 = pow(cbarp, 7.0);
    double rc = 2.0 * sqrt(cbarp7 / (cbarp7 + pow(25.0, 7.0)));
    double sl = 1.0 + 0.015 * pow(lbarp - 50.0, 2.0) / sqrt(20.0 + pow(lbarp - 50.0, 2.0));
    double sc = 1.0 + 0.045 * cbarp, sh = 1.0 + 0.015 * cbarp * t;
    double rt = -sin(rad(2.0 * dtheta)) * rc;
    double x = dlp / sl, y = dcp / sc, z = dHp / sh;
    return sqrt(x * x + y * y + z * z + rt * y * z);
}
