build2/host_sim/tt_ctrl.o: host_sim/tt_ctrl.c host_sim/tt_ctrl.h \
 hal/modbus/tt_regs.h
host_sim/tt_ctrl.h:
hal/modbus/tt_regs.h:
