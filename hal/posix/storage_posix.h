/* POSIX storage backend, shared by every board. */
#ifndef STORAGE_POSIX_H
#define STORAGE_POSIX_H
#include "hal.h"
/** Fill @p st with the POSIX backend. */
void storage_posix_init(struct hal_storage *st);
#endif
