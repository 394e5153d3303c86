build2/firmware/lens.o: firmware/lens.c firmware/lens.h
firmware/lens.h:
