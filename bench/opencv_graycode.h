/* OpenCV 4's structured_light::GrayCodePattern, wrapped for the C benchmark. */
#ifndef OPENCV_GRAYCODE_H
#define OPENCV_GRAYCODE_H

#ifdef __cplusplus
extern "C" {
#endif

/** Generate OpenCV's patterns for a proj_w x proj_h projector; count how many projector pixels
 *  differ from @p lit (our pattern k + 2, white and black being our first two).
 *  @param count out: number of OpenCV patterns */
long opencv_graycode_pattern_mismatches(int proj_w, int proj_h, int *count,
                                        int (*lit)(void *ctx, unsigned index, unsigned column,
                                                   unsigned row),
                                        void *ctx);

/** getProjPixel for every pixel of @p count frames (OpenCV's order). @retval milliseconds */
double opencv_graycode_decode(const unsigned char *const *frames, int count, int width, int height,
                              int proj_w, int proj_h, int white_threshold, unsigned short *column,
                              unsigned short *row, unsigned char *valid);

#ifdef __cplusplus
}
#endif

#endif
