build2/app/scan_dir_range.o: app/scan_dir_range.c app/scan_dir.h \
 firmware/colour.h firmware/decode.h firmware/gray.h \
 firmware/scan_types.h hal/include/hal_limits.h firmware/tri.h \
 firmware/decode.h hal/include/hal.h hal/include/hal_camera.h \
 hal/include/hal_clock.h hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h firmware/reg.h \
 firmware/align.h firmware/frames.h firmware/vec3.h firmware/scan.h \
 firmware/colour.h firmware/reg.h firmware/scan_types.h \
 hal/posix/file_posix.h
app/scan_dir.h:
firmware/colour.h:
firmware/decode.h:
firmware/gray.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/tri.h:
firmware/decode.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
firmware/reg.h:
firmware/align.h:
firmware/frames.h:
firmware/vec3.h:
firmware/scan.h:
firmware/colour.h:
firmware/reg.h:
firmware/scan_types.h:
hal/posix/file_posix.h:
