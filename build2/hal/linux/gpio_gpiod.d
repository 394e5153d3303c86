build2/hal/linux/gpio_gpiod.o: hal/linux/gpio_gpiod.c \
 hal/linux/gpio_gpiod.h hal/include/hal.h hal/include/hal_camera.h \
 hal/include/hal_clock.h hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h
hal/linux/gpio_gpiod.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
