build2/board/board_sim.o: board/board_sim.c board/board.h \
 hal/include/hal.h hal/include/hal_camera.h hal/include/hal_clock.h \
 hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h \
 firmware/scan_types.h hal/include/hal_limits.h firmware/gray.h \
 firmware/scan.h firmware/colour.h firmware/decode.h firmware/gray.h \
 firmware/scan_types.h firmware/tri.h firmware/frames.h firmware/vec3.h \
 firmware/reg.h firmware/align.h hal/posix/clock_posix.h \
 hal/posix/image_io.h host_sim/sim_devices.h host_sim/sim_ctl.h \
 host_sim/sim_rig.h host_sim/sim_config.h host_sim/sim_bvh.h \
 host_sim/sim_mesh.h firmware/vec3.h host_sim/sim_material.h \
 host_sim/sim_target.h host_sim/pty_link.h host_sim/sim_config.h \
 hal/posix/storage_posix.h host_sim/tt_server.h host_sim/tt_ctrl.h \
 hal/modbus/tt_regs.h hal/modbus/turntable_modbus.h
board/board.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/gray.h:
firmware/scan.h:
firmware/colour.h:
firmware/decode.h:
firmware/gray.h:
firmware/scan_types.h:
firmware/tri.h:
firmware/frames.h:
firmware/vec3.h:
firmware/reg.h:
firmware/align.h:
hal/posix/clock_posix.h:
hal/posix/image_io.h:
host_sim/sim_devices.h:
host_sim/sim_ctl.h:
host_sim/sim_rig.h:
host_sim/sim_config.h:
host_sim/sim_bvh.h:
host_sim/sim_mesh.h:
firmware/vec3.h:
host_sim/sim_material.h:
host_sim/sim_target.h:
host_sim/pty_link.h:
host_sim/sim_config.h:
hal/posix/storage_posix.h:
host_sim/tt_server.h:
host_sim/tt_ctrl.h:
hal/modbus/tt_regs.h:
hal/modbus/turntable_modbus.h:
