build2/hal/posix/storage_posix.o: hal/posix/storage_posix.c \
 hal/posix/storage_posix.h hal/include/hal.h hal/include/hal_camera.h \
 hal/include/hal_clock.h hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h
hal/posix/storage_posix.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
