/* sRGB encoding of linear bytes: one table, as the writers call it per vertex. */
#include "srgb.h"

#include <math.h>

/* srgb_encode(i) for i = 0..255: the formula in srgb.h, rounded (tests/test_ply.c checks every
 * entry against it). A table rather than pow() per channel: a fused mesh has ~10^6 channels. */
static const uint8_t encode_table[256] = {
    0,   13,  22,  28,  34,  38,  42,  46,  50,  53,  56,  59,  61,  64,  66,  69,  71,  73,  75,
    77,  79,  81,  83,  85,  86,  88,  90,  92,  93,  95,  96,  98,  99,  101, 102, 104, 105, 106,
    108, 109, 110, 112, 113, 114, 115, 117, 118, 119, 120, 121, 122, 124, 125, 126, 127, 128, 129,
    130, 131, 132, 133, 134, 135, 136, 137, 138, 139, 140, 141, 142, 143, 144, 145, 146, 147, 148,
    148, 149, 150, 151, 152, 153, 154, 155, 155, 156, 157, 158, 159, 159, 160, 161, 162, 163, 163,
    164, 165, 166, 167, 167, 168, 169, 170, 170, 171, 172, 173, 173, 174, 175, 175, 176, 177, 178,
    178, 179, 180, 180, 181, 182, 182, 183, 184, 185, 185, 186, 187, 187, 188, 189, 189, 190, 190,
    191, 192, 192, 193, 194, 194, 195, 196, 196, 197, 197, 198, 199, 199, 200, 200, 201, 202, 202,
    203, 203, 204, 205, 205, 206, 206, 207, 208, 208, 209, 209, 210, 210, 211, 212, 212, 213, 213,
    214, 214, 215, 215, 216, 216, 217, 218, 218, 219, 219, 220, 220, 221, 221, 222, 222, 223, 223,
    224, 224, 225, 226, 226, 227, 227, 228, 228, 229, 229, 230, 230, 231, 231, 232, 232, 233, 233,
    234, 234, 235, 235, 236, 236, 237, 237, 238, 238, 238, 239, 239, 240, 240, 241, 241, 242, 242,
    243, 243, 244, 244, 245, 245, 246, 246, 246, 247, 247, 248, 248, 249, 249, 250, 250, 251, 251,
    251, 252, 252, 253, 253, 254, 254, 255, 255,
};

uint8_t srgb_encode(uint8_t linear)
{
    return encode_table[linear];
}

/* The formula at every 16-bit linear value, made on the first call (64 KB: a pow() per channel
 * of a texture's millions of texels cost a third of its time). */
uint8_t srgb_encode16(uint16_t linear)
{
    static uint8_t fine[65536];
    static int made;
    if (!made) {
        for (int i = 0; i < 65536; i++) {
            double x = (double)i / 65535.0;
            double e = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
            fine[i] = (uint8_t)(255.0 * e + 0.5);
        }
        made = 1;
    }
    return fine[linear];
}

uint8_t srgb_encode_unit(double linear)
{
    double x = linear < 0.0 ? 0.0 : linear > 1.0 ? 1.0 : linear;
    return srgb_encode16((uint16_t)(x * 65535.0 + 0.5)); /* rounded (lround's call cost a third) */
}
