/* The HTTP API under /api (docs/api.md). */
#ifndef API_H
#define API_H

#include "web.h"

struct mg_connection;

/** civetweb's request handler for /api and below; @p cbdata is the struct web_server.
 *  @retval the HTTP status sent */
int api_handle(struct mg_connection *conn, void *cbdata);

#endif
