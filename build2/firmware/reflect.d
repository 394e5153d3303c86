build2/firmware/reflect.o: firmware/reflect.c firmware/reflect.h \
 hal/include/hal.h hal/include/hal_camera.h hal/include/hal_clock.h \
 hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h firmware/lsq.h \
 firmware/frames.h firmware/scan_types.h hal/include/hal_limits.h \
 firmware/vec3.h
firmware/reflect.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
firmware/lsq.h:
firmware/frames.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/vec3.h:
