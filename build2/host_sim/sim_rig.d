build2/host_sim/sim_rig.o: host_sim/sim_rig.c host_sim/sim_rig.h \
 host_sim/sim_config.h hal/include/hal_limits.h firmware/scan_types.h \
 firmware/gray.h host_sim/sim_bvh.h host_sim/sim_mesh.h firmware/vec3.h \
 host_sim/sim_material.h host_sim/sim_target.h firmware/frames.h \
 firmware/scan_types.h firmware/vec3.h firmware/lens.h \
 host_sim/sim_jpeg.h host_sim/sim_random.h
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
firmware/frames.h:
firmware/scan_types.h:
firmware/vec3.h:
firmware/lens.h:
host_sim/sim_jpeg.h:
host_sim/sim_random.h:
