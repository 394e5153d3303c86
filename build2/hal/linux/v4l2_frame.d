build2/hal/linux/v4l2_frame.o: hal/linux/v4l2_frame.c \
 hal/linux/v4l2_frame.h hal/include/hal_camera.h hal/include/hal_limits.h
hal/linux/v4l2_frame.h:
hal/include/hal_camera.h:
hal/include/hal_limits.h:
