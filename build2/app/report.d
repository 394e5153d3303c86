build2/app/report.o: app/report.c app/report.h hal/include/hal.h \
 hal/include/hal_camera.h hal/include/hal_clock.h hal/include/hal_gpio.h \
 hal/include/hal_limits.h hal/include/hal_storage.h \
 hal/include/hal_turntable.h hal/posix/file_posix.h firmware/decode.h \
 firmware/gray.h firmware/scan_types.h hal/include/hal_limits.h \
 hal/posix/image_io.h app/scan_dir.h firmware/colour.h firmware/decode.h \
 firmware/tri.h firmware/reg.h firmware/align.h firmware/frames.h \
 firmware/vec3.h firmware/scan.h firmware/colour.h firmware/reg.h \
 firmware/scan_types.h firmware/srgb.h
app/report.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
hal/posix/file_posix.h:
firmware/decode.h:
firmware/gray.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
hal/posix/image_io.h:
app/scan_dir.h:
firmware/colour.h:
firmware/decode.h:
firmware/tri.h:
firmware/reg.h:
firmware/align.h:
firmware/frames.h:
firmware/vec3.h:
firmware/scan.h:
firmware/colour.h:
firmware/reg.h:
firmware/scan_types.h:
firmware/srgb.h:
