build2/tests/test_reg.o: tests/test_reg.c firmware/camray.h \
 firmware/scan_types.h hal/include/hal_limits.h firmware/vec3.h \
 app/config.h board/board.h hal/include/hal.h hal/include/hal_camera.h \
 hal/include/hal_clock.h hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h \
 firmware/scan_types.h app/calib_file.h app/calib_settings.h \
 firmware/fusion.h firmware/decode.h firmware/gray.h firmware/frames.h \
 firmware/tri.h firmware/reg.h firmware/align.h app/scan_dir.h \
 firmware/colour.h firmware/decode.h firmware/scan.h firmware/colour.h \
 firmware/reg.h app/ini_schema.h host_sim/sim_config.h \
 hal/modbus/turntable_modbus.h firmware/vec3.h firmware/lsq.h
firmware/camray.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/vec3.h:
app/config.h:
board/board.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
firmware/scan_types.h:
app/calib_file.h:
app/calib_settings.h:
firmware/fusion.h:
firmware/decode.h:
firmware/gray.h:
firmware/frames.h:
firmware/tri.h:
firmware/reg.h:
firmware/align.h:
app/scan_dir.h:
firmware/colour.h:
firmware/decode.h:
firmware/scan.h:
firmware/colour.h:
firmware/reg.h:
app/ini_schema.h:
host_sim/sim_config.h:
hal/modbus/turntable_modbus.h:
firmware/vec3.h:
firmware/lsq.h:
