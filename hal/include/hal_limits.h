/* Compile-time limits shared by the HAL and the firmware: every static buffer is sized from here.
 */
#ifndef HAL_LIMITS_H
#define HAL_LIMITS_H

#include <stddef.h>
#include <stdint.h>

#ifdef HAL_LIMITS_SMALL
/* make LIMITS=small, for a board with 512 MB (a Pi Zero 2 W, a Pi 3A+): frames up to the Pi
 * camera v1's 2x2 binned mode, 1296 x 972, and a smaller fusion grid (fusion.h); about 290 MiB
 * of static buffers instead of 657. */
#define HAL_MAX_WIDTH 1296u
#define HAL_MAX_HEIGHT 972u
#else
/* The Raspberry Pi HQ camera's 2x2 binned mode is 2028 x 1520; leave room for it. */
#define HAL_MAX_WIDTH 2048u
#define HAL_MAX_HEIGHT 1536u
#endif
#define HAL_MAX_PIXELS (HAL_MAX_WIDTH * HAL_MAX_HEIGHT)
/* White lights around the object (Jost et al. method 3 needs several). */
#define HAL_MAX_LIGHTS 8u
/* Projector columns are coded with at most 11 Gray-code bits (2048 columns). */
#define HAL_MAX_PROJECTOR_WIDTH 2048u
#define HAL_MAX_PROJECTOR_HEIGHT 2048u
#define HAL_MAX_PATH 512u
/* Largest stack frame a firmware/ function may have (gcc -fstack-usage, checked by make test:
 * scripts/check-stack.sh); big state lives in static buffers, never on the stack. */
#define HAL_STACK_FRAME_MAX 2048u

#ifdef __cplusplus /* the libcamera backend is C++ */
#define HAL_STATIC_ASSERT static_assert
#else
#define HAL_STATIC_ASSERT _Static_assert
#endif

HAL_STATIC_ASSERT(HAL_MAX_WIDTH % 2u == 0u, "YUYV conversion needs an even width");
HAL_STATIC_ASSERT(HAL_MAX_PIXELS <= (1u << 23), "pixel indices must fit comfortably in 32 bits");
HAL_STATIC_ASSERT(HAL_MAX_PROJECTOR_WIDTH <= 65535u, "projector columns are stored as uint16_t");

#endif
