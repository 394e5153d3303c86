/* JPEG round trip of a simulated frame with libjpeg(-turbo): the blocking and ringing a camera's
 * MJPEG stream adds, made by the real codec rather than imitated. */
#include "sim_jpeg.h"

#include <errno.h>
#include <setjmp.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jpeglib.h>

struct jpeg_fail {
    struct jpeg_error_mgr mgr;
    jmp_buf jump;
};

/* libjpeg's default error handler exits the process; come back here instead. */
static void fail_jump(j_common_ptr info)
{
    longjmp(((struct jpeg_fail *)(void *)info->err)->jump, 1);
}

static int compress(const uint8_t *rgb, uint32_t width, uint32_t height, uint32_t quality,
                    unsigned char **out, unsigned long *out_len)
{
    struct jpeg_compress_struct c;
    struct jpeg_fail fail;
    c.err = jpeg_std_error(&fail.mgr);
    fail.mgr.error_exit = fail_jump;
    if (setjmp(fail.jump)) {
        jpeg_destroy_compress(&c);
        return -EIO;
    }
    jpeg_create_compress(&c);
    jpeg_mem_dest(&c, out, out_len);
    c.image_width = width;
    c.image_height = height;
    c.input_components = 3;
    c.in_color_space = JCS_RGB;
    jpeg_set_defaults(&c); /* YCbCr, 4:2:0 */
    jpeg_set_quality(&c, (int)quality, TRUE);
    jpeg_start_compress(&c, TRUE);
    while (c.next_scanline < height) {
        JSAMPROW row = (JSAMPROW)(rgb + (size_t)c.next_scanline * width * 3);
        jpeg_write_scanlines(&c, &row, 1);
    }
    jpeg_finish_compress(&c);
    jpeg_destroy_compress(&c);
    return 0;
}

static int decompress(const unsigned char *data, unsigned long len, uint8_t *rgb, uint32_t width,
                      uint32_t height)
{
    struct jpeg_decompress_struct d;
    struct jpeg_fail fail;
    d.err = jpeg_std_error(&fail.mgr);
    fail.mgr.error_exit = fail_jump;
    if (setjmp(fail.jump)) {
        jpeg_destroy_decompress(&d);
        return -EIO;
    }
    jpeg_create_decompress(&d);
    jpeg_mem_src(&d, data, len);
    jpeg_read_header(&d, TRUE);
    d.out_color_space = JCS_RGB;
    jpeg_start_decompress(&d);
    if (d.output_width != width || d.output_height != height || d.output_components != 3) {
        jpeg_destroy_decompress(&d);
        return -EIO;
    }
    while (d.output_scanline < height) {
        JSAMPROW row = (JSAMPROW)(rgb + (size_t)d.output_scanline * width * 3);
        jpeg_read_scanlines(&d, &row, 1);
    }
    jpeg_finish_decompress(&d);
    jpeg_destroy_decompress(&d);
    return 0;
}

int sim_jpeg_roundtrip(uint8_t *rgb, uint32_t width, uint32_t height, uint32_t quality)
{
    unsigned char *data = NULL;
    unsigned long len = 0;
    int rc = compress(rgb, width, height, quality, &data, &len);
    if (rc == 0)
        rc = decompress(data, len, rgb, width, height);
    free(data); /* jpeg_mem_dest's buffer, also after a failure part way */
    return rc;
}
