/* The events of a scan job, one name each: the "event" of each line scanner --json writes
 * (docs/api.md), said by the job (job_events.c) and read by the web server (web/jobs.c). */
#ifndef SCAN_EVENTS_H
#define SCAN_EVENTS_H

#define EV_SCAN_START "scan_start"       /* a scan begins: the folder */
#define EV_RESUME "resume"               /* a resume begins: the views kept */
#define EV_PROCESS_START "process_start" /* process begins */
#define EV_HOMING "homing"               /* the table homes */
#define EV_MOVING "moving"               /* the table turns to a view */
#define EV_CAPTURING "capturing"         /* a view's frames are taken */
#define EV_SAVING "saving"               /* a view taken is decoded and kept */
#define EV_SAVED "saved"                 /* a view is complete (its view.ini written) */
#define EV_PLACE_OBJECT "place_object"   /* the person lays the object for the second pass */
#define EV_DECODED "decoded"             /* process: a view decoded again */
#define EV_REGISTRATION "registration"   /* the views registered jointly */
#define EV_REFLECTANCE "reflectance"     /* the reflectance fitted ([colour] method = fit) */
#define EV_FUSED "fused"                 /* a view fused into the model */
#define EV_MESHING "meshing"             /* marching cubes begins */
#define EV_MESH "mesh"                   /* the mesh written */
#define EV_COST "cost"                   /* what the job cost (make bench reads it) */
#define EV_SCAN_DONE "scan_done"         /* the scan finished: every output written */
#define EV_SCAN_FAILED "scan_failed"     /* the scan failed (--json) */
#define EV_PROCESS_DONE "process_done"   /* process finished */

#endif
