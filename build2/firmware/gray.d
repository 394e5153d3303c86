build2/firmware/gray.o: firmware/gray.c firmware/gray.h
firmware/gray.h:
