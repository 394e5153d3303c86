// OpenCV's structured-light Gray-code decoder behind a C interface, for the benchmark only (the
// scanner never links OpenCV).
#include "opencv_graycode.h"

#include <chrono>
#include <opencv2/core.hpp>
#include <opencv2/structured_light.hpp>
#include <vector>

using cv::structured_light::GrayCodePattern;

static cv::Ptr<GrayCodePattern> make(int proj_w, int proj_h)
{
    GrayCodePattern::Params params;
    params.width = proj_w;
    params.height = proj_h;
    return GrayCodePattern::create(params);
}

extern "C" long opencv_graycode_pattern_mismatches(int proj_w, int proj_h, int *count,
                                                   int (*lit)(void *ctx, unsigned index,
                                                              unsigned column, unsigned row),
                                                   void *ctx)
{
    std::vector<cv::Mat> patterns;
    make(proj_w, proj_h)->generate(patterns);
    *count = (int)patterns.size();
    long bad = 0;
    for (size_t k = 0; k < patterns.size(); k++)
        for (int r = 0; r < proj_h; r++)
            for (int c = 0; c < proj_w; c++)
                bad += (patterns[k].at<uchar>(r, c) != 0) != (lit(ctx, (unsigned)k, c, r) != 0);
    return bad;
}

extern "C" double opencv_graycode_decode(const unsigned char *const *frames, int count, int width,
                                         int height, int proj_w, int proj_h, int white_threshold,
                                         unsigned short *column, unsigned short *row,
                                         unsigned char *valid)
{
    cv::Ptr<GrayCodePattern> gc = make(proj_w, proj_h);
    gc->setWhiteThreshold((size_t)white_threshold);
    std::vector<cv::Mat> images;
    for (int k = 0; k < count; k++) // headers over our frames: no copy
        images.emplace_back(height, width, CV_8UC1, const_cast<unsigned char *>(frames[k]));
    auto t0 = std::chrono::steady_clock::now();
    for (int y = 0; y < height; y++) {
        for (int x = 0; x < width; x++) {
            cv::Point p;
            bool error = gc->getProjPixel(images, x, y, p); // true means it failed
            size_t i = (size_t)y * width + x;
            valid[i] = !error;
            column[i] = (unsigned short)p.x;
            row[i] = (unsigned short)p.y;
        }
    }
    auto t1 = std::chrono::steady_clock::now();
    return std::chrono::duration<double, std::milli>(t1 - t0).count();
}
