build2/hal/modbus/turntable_modbus.o: hal/modbus/turntable_modbus.c \
 hal/modbus/turntable_modbus.h hal/include/hal.h hal/include/hal_camera.h \
 hal/include/hal_clock.h hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h \
 hal/modbus/tt_regs.h /usr/include/modbus/modbus.h \
 /usr/include/modbus/modbus-version.h /usr/include/modbus/modbus-tcp.h \
 /usr/include/modbus/modbus.h /usr/include/modbus/modbus-rtu.h
hal/modbus/turntable_modbus.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
hal/modbus/tt_regs.h:
/usr/include/modbus/modbus.h:
/usr/include/modbus/modbus-version.h:
/usr/include/modbus/modbus-tcp.h:
/usr/include/modbus/modbus.h:
/usr/include/modbus/modbus-rtu.h:
