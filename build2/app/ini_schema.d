build2/app/ini_schema.o: app/ini_schema.c app/ini_schema.h \
 hal/posix/file_posix.h hal/include/hal_gpio.h hal/include/hal_limits.h
app/ini_schema.h:
hal/posix/file_posix.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
