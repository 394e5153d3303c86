/* One camera frame for a board's selftest: open, capture, close, whatever the backend. */
#include "board.h"

#include <errno.h>
#include <stdlib.h>

int board_grab_frame(const struct hal *hal, const struct hal_camera_config *cam, uint32_t *width,
                     uint32_t *height)
{
    struct hal_image img = {0};
    img.capacity = (size_t)cam->width * cam->height * 3u;
    img.rgb = malloc(img.capacity); /* once, at start: the app may allocate, firmware/ not */
    int rc = img.rgb == NULL ? -ENOMEM : hal_cam_open(&hal->camera, cam);
    if (rc == 0)
        rc = hal_cam_capture(&hal->camera, &img);
    *width = img.width;
    *height = img.height;
    hal_cam_close(&hal->camera);
    free(img.rgb);
    return rc;
}
