build2/app/calib_file.o: app/calib_file.c app/calib_file.h \
 hal/include/hal.h hal/include/hal_camera.h hal/include/hal_clock.h \
 hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h \
 firmware/scan_types.h hal/include/hal_limits.h hal/posix/file_posix.h \
 app/ini_schema.h firmware/vec3.h
app/calib_file.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
hal/posix/file_posix.h:
app/ini_schema.h:
firmware/vec3.h:
