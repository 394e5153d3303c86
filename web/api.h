/* The HTTP API under /api (docs/api.md). */
#ifndef API_H
#define API_H

#include "web.h"

#include <cJSON.h>

struct mg_connection;

/** civetweb's request handler for /api and below; @p cbdata is the struct web_server.
 *  @retval the HTTP status sent */
int api_handle(struct mg_connection *conn, void *cbdata);

/* ---- for the other request files of the API (profiles.c) ---- */

/** Send @p body (consumed) with @p status. @retval status */
int api_send_json(struct mg_connection *conn, int status, cJSON *body);

/** Send {"error": @p message} with @p status. @retval status */
int api_send_error(struct mg_connection *conn, int status, const char *message);

/** @retval 1 the request carries the session key (it may change the rig or its settings) */
int api_may_use_rig(const struct web_server *s, const struct mg_connection *conn);

/** The request's body as one JSON object (bounded: WEB_MAX_BODY, 32 deep, nothing after it).
 *  @retval 0 @retval 400, 413 or 415 (@p body NULL or to be freed) */
int api_read_body(struct mg_connection *conn, cJSON **body);

/** /api/profiles/NAME: GET its main settings, POST them changed (profiles.c).
 *  @retval the HTTP status sent */
int profiles_handle(struct mg_connection *conn, struct web_server *s, const char *method,
                    const char *name);

#endif
