build2/firmware/refine.o: firmware/refine.c firmware/refine.h \
 firmware/decode.h firmware/gray.h firmware/scan_types.h \
 hal/include/hal_limits.h
firmware/refine.h:
firmware/decode.h:
firmware/gray.h:
firmware/scan_types.h:
hal/include/hal_limits.h:
