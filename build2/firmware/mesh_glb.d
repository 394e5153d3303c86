build2/firmware/mesh_glb.o: firmware/mesh_glb.c firmware/fusion.h \
 firmware/decode.h firmware/gray.h firmware/scan_types.h \
 hal/include/hal_limits.h firmware/frames.h firmware/vec3.h \
 hal/include/hal.h hal/include/hal_camera.h hal/include/hal_clock.h \
 hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h firmware/tri.h \
 firmware/outbuf.h firmware/reflect.h
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
firmware/outbuf.h:
firmware/reflect.h:
