/* A camera's JPEG stream in the simulator: a frame compressed and decoded again (libjpeg). */
#ifndef SIM_JPEG_H
#define SIM_JPEG_H

#include <stdint.h>

/** Replace the RGB24 frame @p rgb (@p width x @p height) by its JPEG round trip at @p quality
 *  (1..100, libjpeg's scale; 4:2:0 chroma as most cameras stream).
 *  @retval 0 ok @retval -ENOMEM @retval -EIO libjpeg refused (the frame is left as it was) */
int sim_jpeg_roundtrip(uint8_t *rgb, uint32_t width, uint32_t height, uint32_t quality);

#endif
