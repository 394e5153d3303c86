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

/** Send 403: a request that uses the rig without the session key. @retval 403 */
int api_refuse_without_key(struct mg_connection *conn);

/** Send @p len bytes of PNG, not to be cached. @retval 200 */
int api_send_png(struct mg_connection *conn, const void *png, size_t len);

/** Send what is wrong with a body api_read_body refused with @p status. @retval status */
int api_send_body_error(struct mg_connection *conn, int status);

/** The profile called @p name. @retval NULL no such one */
const struct web_profile *api_profile_named(const struct web_server *s, const char *name);

/** The profile a body names ("profile"; none: the first served). @retval NULL no such one */
const struct web_profile *api_find_profile(const struct web_server *s, const cJSON *body);

/** /api/calibration and below (calibration.c): the calibration wizard's requests; @p rest is
 *  "" or "/answer" and the like. @retval the HTTP status sent */
int calibration_handle(struct mg_connection *conn, struct web_server *s, const char *method,
                       const char *rest);

/** /api/profiles/NAME: GET its main settings, POST them changed (profiles.c).
 *  @retval the HTTP status sent */
int profiles_handle(struct mg_connection *conn, struct web_server *s, const char *method,
                    const char *name);

#endif
