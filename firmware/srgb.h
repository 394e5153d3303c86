/* The sRGB transfer function for colours people look at: the scanner computes and fuses colour
 * in linear units (albedo), while viewers show a file's 8-bit colours as sRGB-encoded. */
#ifndef SRGB_H
#define SRGB_H

#include <stdint.h>

/** The sRGB encoding of a linear byte (IEC 61966-2-1: 12.92 x below 0.0031308, else
 *  1.055 x^(1/2.4) - 0.055), both as 0..255, rounded.
 *  @param linear  linear value 0..255 @retval the sRGB-encoded value 0..255 */
uint8_t srgb_encode(uint8_t linear);

/** The same for a 16-bit linear value (0..65535): a linear byte b given as b x 257 is encoded as
 *  srgb_encode(b). Its table is made on the first call: make that call from one thread.
 *  @retval the sRGB-encoded value 0..255 */
uint8_t srgb_encode16(uint16_t linear);

/** The same for a linear value 0..1 (clamped), to the nearest 16-bit step: a texture's colour
 *  averaged over views keeps the shades between two linear bytes (in the dark a linear byte is
 *  a step of 5 sRGB values). Its table is srgb_encode16's. @retval the sRGB-encoded value
 *  0..255 */
uint8_t srgb_encode_unit(double linear);

#endif
