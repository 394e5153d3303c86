/* White reference: per-channel scales that make a white target of known albedo come out right. */
#ifndef WHITE_CAL_H
#define WHITE_CAL_H

#include "config.h"
#include "hal.h"
#include "scan.h"

/** Scale of each compensation method (index enum colour_method; [0] unused), per channel. */
struct white_cal {
    double scale[4][3];
    uint32_t pixels[4]; /**< confident pixels the median came from */
};

/** From @p view (taken with every colour frame; recoloured in place by each method in turn):
 *  for each method, the scale that maps the median compensated colour of the confident pixels
 *  to @p target_albedo.
 *  @retval 0 @retval -EINVAL no confident pixel for some method */
int white_cal_from_view(const struct app_config *cfg, const struct scan_calib *calib,
                        struct scan_view *view, double target_albedo, struct white_cal *out);

#endif
