build2/firmware/colour.o: firmware/colour.c firmware/colour.h \
 firmware/decode.h firmware/gray.h firmware/scan_types.h \
 hal/include/hal_limits.h firmware/tri.h firmware/reflect.h \
 hal/include/hal.h hal/include/hal_camera.h hal/include/hal_clock.h \
 hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h firmware/vec3.h
firmware/colour.h:
firmware/decode.h:
firmware/gray.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/tri.h:
firmware/reflect.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
firmware/vec3.h:
