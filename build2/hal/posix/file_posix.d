build2/hal/posix/file_posix.o: hal/posix/file_posix.c \
 hal/posix/file_posix.h
hal/posix/file_posix.h:
