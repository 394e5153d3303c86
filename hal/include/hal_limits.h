/* Every compile-time limit, in one place: the HAL's frame and device sizes and the firmware's
 * buffers are all sized from here, and checked against each other below. A config beyond them
 * is refused at start with a message naming the limit (scan_check, fusion_dims, config_load). */
#ifndef HAL_LIMITS_H
#define HAL_LIMITS_H

#include <stddef.h>
#include <stdint.h>

#ifdef HAL_LIMITS_SMALL
/* make LIMITS=small, for a board with 512 MB (a Pi Zero 2 W, a Pi 3A+): frames up to the Pi
 * camera v1's 2x2 binned mode, 1296 x 972, a smaller fusion grid (fusion.h), no bracketed
 * colour frames; about 271 MiB of static buffers instead of 633 (make size). */
#define HAL_MAX_WIDTH 1296u
#define HAL_MAX_HEIGHT 972u
#define HAL_LARGER_FRAMES                                                                          \
    ", or more of it with 'make' (frames up to 2048 x 1536) or 'make LIMITS=large' (4928 x 3456, " \
    "a board with 2 GB or more)"
#elif defined(HAL_LIMITS_LARGE)
/* make LIMITS=large, for a board with 2 GB or more (about 1.8 GB of static buffers, mapped as
 * they are used): full-resolution frames of the sensors people put on these rigs, the
 * Raspberry Pi HQ camera's 4056 x 3040, Camera Module 3's 4608 x 2592, a 16 MP 4608 x 3456 and
 * the 4896 x 3264 of a DSLR (docs/performance.md). */
#define HAL_MAX_WIDTH 4928u
#define HAL_MAX_HEIGHT 3456u
#define HAL_LARGER_FRAMES ""
#else
/* The Raspberry Pi HQ camera's 2x2 binned mode is 2028 x 1520; leave room for it. */
#define HAL_MAX_WIDTH 2048u
#define HAL_MAX_HEIGHT 1536u
#define HAL_LARGER_FRAMES                                                                          \
    ", or the whole frame with 'make LIMITS=large' (up to 4928 x 3456, a board with 2 GB or "      \
    "more)"
#endif
#define HAL_MAX_PIXELS (HAL_MAX_WIDTH * HAL_MAX_HEIGHT)
/* What a person whose camera's frames exceed the limits can do (a config's error says it). */
#define HAL_FRAME_LIMIT_ADVICE                                                                     \
    "a larger sensor: [camera] binning = 2, 3 or 4 (width, height and calibration of the binned "  \
    "frame)" HAL_LARGER_FRAMES
/* [camera] binning: a sensor frame up to this many times the frame, each way, binned down. */
#define HAL_MAX_BINNING 4u
/* White lights around the object (Jost et al. method 3 needs several). */
#define HAL_MAX_LIGHTS 8u
/* Projector columns are coded with at most 11 Gray-code bits (2048 columns). */
#define HAL_MAX_PROJECTOR_WIDTH 2048u
#define HAL_MAX_PROJECTOR_HEIGHT 2048u
#define HAL_MAX_PATH 512u
/* Bits of a Gray-coded projector coordinate: enough for HAL_MAX_PROJECTOR_WIDTH and _HEIGHT. */
#define HAL_MAX_CODE_BITS 11u

/* ---- firmware/ buffers ---- */
/* Frames a view's decoder keeps: white, black, and every column and row bit with its inverse. */
#define DECODE_MAX_PATTERNS (2u + 2u * (HAL_MAX_CODE_BITS + HAL_MAX_CODE_BITS))
/* Colour frames after the patterns (colour.h): dark, all lights, each light alone at its
 * exposure and, with [colour] bracket, at a longer one, and more dark frames for the other
 * exposures (two, three with bracketing). A 512 MB board has no room for the bracketed frames
 * (4 MB each). */
#ifdef HAL_LIMITS_SMALL
#define COLOUR_MAX_BRACKETED 0u
#else
#define COLOUR_MAX_BRACKETED HAL_MAX_LIGHTS /* lights that can be bracketed */
#endif
#define COLOUR_MAX_FRAMES                                                                          \
    (2u + HAL_MAX_LIGHTS + 2u + (COLOUR_MAX_BRACKETED > 0u ? COLOUR_MAX_BRACKETED + 1u : 0u))
/* The memory a view's colour frames are kept in, in frames at the compiled frame limit; smaller
 * frames are packed, so more of them fit. It shares its memory with the fusion volume (app/job.c),
 * which is the larger of the two except at LIMITS=large, where every light bracketed at 16 MP
 * would take 1 GB: there it holds 13 frames (a dark and an all-lights frame, four lights alone
 * and bracketed, their three dark frames), as much as the volume's 639 MiB, so that the build
 * starts on a 2 GB board. A config whose frames do not fit is refused at start (scan_check). */
#ifdef HAL_LIMITS_LARGE
#define COLOUR_POOL_FRAMES 13u
#else
#define COLOUR_POOL_FRAMES COLOUR_MAX_FRAMES
#endif
/* The fusion grid (fusion.h): at most FUSION_MAX_DIM voxels along an axis, FUSION_MAX_VOXELS in
 * all, 8 bytes each. */
#ifdef HAL_LIMITS_SMALL
#define FUSION_MAX_DIM 320u
#define FUSION_MAX_VOXELS (256u * 256u * 224u)
#elif defined(HAL_LIMITS_LARGE) /* and, spent, the atlas of a 16 MP camera's pixels */
#define FUSION_MAX_DIM 400u
#define FUSION_MAX_VOXELS (400u * 400u * 320u)
#else
#define FUSION_MAX_DIM 400u
#define FUSION_MAX_VOXELS (320u * 320u * 280u)
#endif
/* Vertices of the fused mesh that fit the mesh writers' tables (mesh_io.c: the mesh extracted
 * once for every output, its fragments, STL), 35 bytes each, and its triangles, 12 bytes each
 * (a closed surface has about two per vertex); a larger mesh is still written as PLY and OBJ,
 * whole, extracted again for each. */
#ifdef HAL_LIMITS_SMALL
#define MESH_MAX_VERTICES (1u << 19)
#else
#define MESH_MAX_VERTICES (2u << 20)
#endif
#define MESH_MAX_TRIANGLES (2u * MESH_MAX_VERTICES)
/* The texture atlas (atlas.h): its longer side and its texels, and its charts. It costs no memory
 * of its own: it is made in the fusion grid's, spent once the mesh is, beside the vertices'
 * colours from the views (atlas.c asserts it fits). 3 M texels hold 0.27 m^2 of surface at
 * 0.3 mm (a camera pixel at 600 mm), less the packing's waste; a larger surface gets a coarser
 * texel, said. The bunny of make run has 370 charts. */
#ifdef HAL_LIMITS_SMALL
#define ATLAS_MAX_SIDE 2048u
#define ATLAS_MAX_TEXELS (2u << 20)
#elif defined(HAL_LIMITS_LARGE)
#define ATLAS_MAX_SIDE 4096u
#define ATLAS_MAX_TEXELS (4u << 20)
#else
#define ATLAS_MAX_SIDE 4096u
#define ATLAS_MAX_TEXELS (3u << 20)
#endif
#define ATLAS_MAX_CHARTS (1u << 15)
/* [colour] method = fit (reflect.h): the light x view samples its lobes are fitted from, ~180
 * bytes each. */
#ifdef HAL_LIMITS_SMALL
#define REFLECT_MAX_SAMPLES 16384u
#else
#define REFLECT_MAX_SAMPLES 32768u
#endif
#define REFLECT_MAX_CLUSTERS 8u /* material clusters, each with its specular lobe */
/* Joint registration (reg.h): the views of one scan (as many as [scan] views allows), and the
 * samples kept of all of them together, 32 bytes each; a scan of many views keeps every n-th
 * pixel with a larger n. */
#define REG_MAX_VIEWS 360u
#ifdef HAL_LIMITS_SMALL /* 8 views of 1280 x 960 at every 4th pixel, as the default build */
#define REG_MAX_CELLS (640u * 1024u)
#else
#define REG_MAX_CELLS (1u << 20)
#endif
/* A second pass aligned to the first (align.h): points kept of each pass, 24 bytes each, and
 * the cells of the first pass's nearest-point field, 4 bytes each. */
#ifdef HAL_LIMITS_SMALL
#define ALIGN_MAX_POINTS 75000u
#define ALIGN_MAX_CELLS (1u << 20)
#else
#define ALIGN_MAX_POINTS 150000u
#define ALIGN_MAX_CELLS (1u << 21)
#endif
/* Threads a per-pixel stage may use (hal_thread.h): [scan] threads is checked against it. */
#define HAL_MAX_THREADS 8u

/* Largest stack frame a firmware/ function may have (gcc -fstack-usage, checked by make test:
 * scripts/check-stack.sh); big state lives in static buffers, never on the stack. */
#define HAL_STACK_FRAME_MAX 2048u

#ifdef __cplusplus /* the libcamera backend is C++ */
#define HAL_STATIC_ASSERT static_assert
#else
#define HAL_STATIC_ASSERT _Static_assert
#endif

HAL_STATIC_ASSERT(HAL_MAX_WIDTH % 2u == 0u, "YUYV conversion needs an even width");
HAL_STATIC_ASSERT(HAL_MAX_PIXELS <= (1u << 25), "pixel indices must fit comfortably in 32 bits");
HAL_STATIC_ASSERT(HAL_MAX_PROJECTOR_WIDTH <= 65535u, "projector columns are stored as uint16_t");
HAL_STATIC_ASSERT((1u << HAL_MAX_CODE_BITS) >= HAL_MAX_PROJECTOR_WIDTH &&
                      (1u << HAL_MAX_CODE_BITS) >= HAL_MAX_PROJECTOR_HEIGHT,
                  "every projector column and row must have a code");
HAL_STATIC_ASSERT(DECODE_MAX_PATTERNS <= 255u, "pattern indices are counted in small integers");
HAL_STATIC_ASSERT(HAL_MAX_LIGHTS <= 31u, "light masks are 32-bit words");
HAL_STATIC_ASSERT(COLOUR_POOL_FRAMES <= COLOUR_MAX_FRAMES, "the pool holds at most every frame");
HAL_STATIC_ASSERT(FUSION_MAX_VOXELS <= (uint64_t)FUSION_MAX_DIM * FUSION_MAX_DIM * FUSION_MAX_DIM,
                  "the voxel budget fits in a grid of the largest dimensions");
HAL_STATIC_ASSERT(REG_MAX_CELLS / REG_MAX_VIEWS >= 64u, "every view keeps some samples");
HAL_STATIC_ASSERT((uint64_t)FUSION_MAX_VOXELS * 3u < (1ull << 32),
                  "a mesh vertex per voxel edge (3 a voxel) is numbered in 32 bits");

#endif
