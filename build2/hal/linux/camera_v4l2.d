build2/hal/linux/camera_v4l2.o: hal/linux/camera_v4l2.c \
 hal/linux/camera_v4l2.h hal/include/hal.h hal/include/hal_camera.h \
 hal/include/hal_clock.h hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h \
 hal/linux/v4l2_frame.h hal/include/hal_camera.h
hal/linux/camera_v4l2.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
hal/linux/v4l2_frame.h:
hal/include/hal_camera.h:
