build2/firmware/scan.o: firmware/scan.c firmware/scan.h firmware/colour.h \
 firmware/decode.h firmware/gray.h firmware/scan_types.h \
 hal/include/hal_limits.h firmware/tri.h hal/include/hal.h \
 hal/include/hal_camera.h hal/include/hal_clock.h hal/include/hal_gpio.h \
 hal/include/hal_limits.h hal/include/hal_storage.h \
 hal/include/hal_turntable.h firmware/frames.h firmware/vec3.h \
 firmware/reg.h firmware/align.h firmware/fusion.h firmware/ply.h \
 firmware/refine.h
firmware/scan.h:
firmware/colour.h:
firmware/decode.h:
firmware/gray.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/tri.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
firmware/frames.h:
firmware/vec3.h:
firmware/reg.h:
firmware/align.h:
firmware/fusion.h:
firmware/ply.h:
firmware/refine.h:
