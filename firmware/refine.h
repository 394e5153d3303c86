/* Sub-stripe refinement: a continuous projector column per pixel from the runs of equal codes. */
#ifndef REFINE_H
#define REFINE_H

#include "decode.h"

struct hal_thread;

/** Fill the continuous column map from the decoded integer columns. Along each camera row a
 *  run of pixels with code c that lies between runs coded c - 1 and c + 1 (either order) spans
 *  the projector interval [c - 0.5, c + 0.5]; each pixel gets its linear position in it. Other
 *  pixels keep c. With @p enabled = 0 every pixel keeps c.
 *  @param threads  the cores the rows are split across (NULL: this thread); rows are independent
 *  @param columns  out: the continuous column map (width * height, row-major, meaningful where
 *                  the pixel is valid)
 *  @retval 0 */
int refine_columns(const struct decode_maps *maps, const struct hal_thread *threads, int enabled,
                   float *columns);

#endif
