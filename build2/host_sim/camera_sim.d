build2/host_sim/camera_sim.o: host_sim/camera_sim.c \
 host_sim/sim_devices.h hal/include/hal.h hal/include/hal_camera.h \
 hal/include/hal_clock.h hal/include/hal_gpio.h hal/include/hal_limits.h \
 hal/include/hal_storage.h hal/include/hal_turntable.h host_sim/sim_ctl.h \
 host_sim/sim_rig.h host_sim/sim_config.h hal/include/hal_limits.h \
 firmware/scan_types.h firmware/gray.h host_sim/sim_bvh.h \
 host_sim/sim_mesh.h firmware/vec3.h host_sim/sim_material.h \
 host_sim/sim_target.h
host_sim/sim_devices.h:
hal/include/hal.h:
hal/include/hal_camera.h:
hal/include/hal_clock.h:
hal/include/hal_gpio.h:
hal/include/hal_limits.h:
hal/include/hal_storage.h:
hal/include/hal_turntable.h:
host_sim/sim_ctl.h:
host_sim/sim_rig.h:
host_sim/sim_config.h:
hal/include/hal_limits.h:
firmware/scan_types.h:
firmware/gray.h:
host_sim/sim_bvh.h:
host_sim/sim_mesh.h:
firmware/vec3.h:
host_sim/sim_material.h:
host_sim/sim_target.h:
