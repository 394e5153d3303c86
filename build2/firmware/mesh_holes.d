build2/firmware/mesh_holes.o: firmware/mesh_holes.c firmware/fusion.h \
 firmware/decode.h firmware/gray.h firmware/scan_types.h \
 hal/include/hal_limits.h firmware/frames.h firmware/vec3.h \
 hal/include/hal.h hal/include/hal_camera.h hal/include/hal_clock.h \
 hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h firmware/tri.h
firmware/fusion.h:
firmware/decode.h:
firmware/gray.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/frames.h:
firmware/vec3.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
firmware/tri.h:
