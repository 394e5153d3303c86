build2/hal/posix/image_io.o: hal/posix/image_io.c hal/posix/image_io.h \
 hal/include/hal.h hal/include/hal_camera.h hal/include/hal_clock.h \
 hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h \
 hal/posix/file_posix.h /usr/include/libpng16/png.h \
 /usr/include/libpng16/pnglibconf.h /usr/include/libpng16/pngconf.h
hal/posix/image_io.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
hal/posix/file_posix.h:
/usr/include/libpng16/png.h:
/usr/include/libpng16/pnglibconf.h:
/usr/include/libpng16/pngconf.h:
