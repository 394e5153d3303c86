build2/host_sim/tt_server.o: host_sim/tt_server.c host_sim/tt_server.h \
 host_sim/tt_ctrl.h hal/modbus/tt_regs.h /usr/include/modbus/modbus.h \
 /usr/include/modbus/modbus-version.h /usr/include/modbus/modbus-tcp.h \
 /usr/include/modbus/modbus.h /usr/include/modbus/modbus-rtu.h
host_sim/tt_server.h:
host_sim/tt_ctrl.h:
hal/modbus/tt_regs.h:
/usr/include/modbus/modbus.h:
/usr/include/modbus/modbus-version.h:
/usr/include/modbus/modbus-tcp.h:
/usr/include/modbus/modbus.h:
/usr/include/modbus/modbus-rtu.h:
