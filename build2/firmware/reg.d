build2/firmware/reg.o: firmware/reg.c firmware/reg.h firmware/align.h \
 firmware/frames.h firmware/scan_types.h hal/include/hal_limits.h \
 firmware/vec3.h firmware/decode.h firmware/gray.h firmware/tri.h \
 firmware/reg_priv.h firmware/camray.h firmware/lsq.h
firmware/reg.h:
firmware/align.h:
firmware/frames.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
firmware/vec3.h:
firmware/decode.h:
firmware/gray.h:
firmware/tri.h:
firmware/reg_priv.h:
firmware/camray.h:
firmware/lsq.h:
