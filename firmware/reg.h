/* Joint registration of all views of a turntable scan: the views as turns about one axis, the
 * axis re-estimated from the scan's own data and each view's angle free, every neighbouring pair
 * of views (the last back to the first: the loop closure) pulled together by point-to-plane
 * residuals at once, in a context its owner keeps (struct reg_ctx). */
#ifndef REG_H
#define REG_H

#include "align.h"
#include "decode.h"
#include "frames.h"
#include "tri.h"
#include "vec3.h"

struct reg_params {
    uint32_t enabled;              /**< 0: keep the turntable poses */
    uint32_t sample_stride;        /**< keep every n-th pixel of a view in x and y (at least) */
    uint32_t iterations;           /**< Gauss-Newton steps, each with new pairs */
    double max_pair_mm;            /**< a pair farther apart does not couple */
    double max_normal_deg;         /**< nor one whose normals differ more */
    uint32_t use_colour;           /**< 1: colours must agree too (multi-feature matching) */
    double max_colour_dn;          /**< largest per-channel colour difference of a pair */
    uint32_t colour_intrinsic;     /**< 1: the views' colours are intrinsic (compensated for the
                                        light) and compared as they are; 0: raw colours, whose
                                        brightness follows the shading, compared at one
                                        brightness (not a config key: the job sets it) */
    double max_correction_deg;     /**< a view's angle may move this far from the reported one */
    double max_axis_shift_mm;      /**< the axis may move this far from the calibrated one */
    double max_axis_tilt_deg;      /**< and tilt this far */
    double min_coupled_share;      /**< two neighbouring views coupling less of their overlap do
                                        not match: the registration fails and names the view */
    double angle_accuracy_deg;     /**< the table's angles as a prior of this standard deviation: a
                                        turn the geometry does not fix keeps the table's angle */
    double axis_accuracy_mm;       /**< the calibrated axis as a prior: its point across it, one
                                        standard deviation (0: a third of max_axis_shift_mm) */
    double axis_tilt_accuracy_deg; /**< and its direction (0: a third of max_axis_tilt_deg) */
};

/** One view after registration. */
struct reg_view {
    int present;               /**< 0: never added */
    int32_t reported_mdeg;     /**< the angle the table reported */
    double angle_deg;          /**< the angle it is fused at */
    double correction_deg;     /**< angle_deg - reported, relative to view 0's correction */
    uint32_t overlap, coupled; /**< with its neighbours, at the final poses */
    double rms_mm;             /**< point-to-plane residual of its coupled pairs */
    int turn_from_table;       /**< 1: the geometry does not fix its turn (a surface of
                                    revolution, a plane, too little surface shared): the
                                    table's angle is kept */
    int turn_little_shared;    /**< 1, with turn_from_table: the reason is that its pairs
                                    share too little surface to outweigh the table */
    int turn_by_paint;         /**< 1, with turn_from_table: turned from the table's angle to
                                    where its paint agrees with its neighbours' */
    int placed_freely;         /**< 1: the object had moved: placed by its shape alone */
};

/** The whole scan's registration. */
struct reg_report {
    uint32_t views, stride; /**< views added; pixel stride of the kept samples */
    int solved;             /**< 1: the joint adjustment ran (icp = 1, two views or more) */
    int accepted;           /**< 1: its poses are used; 0: the turntable's */
    uint32_t iterations;    /**< steps taken */
    double score_before_mm, score_after_mm; /**< truncated residual over every overlap: the
                                                 square root of mean(min(r, max_pair)^2) */
    double rms_mm;                       /**< point-to-plane residual of all coupled pairs, final */
    double loop_rms_mm;                  /**< of the closing pair (last view back to the first) */
    double axis_shift_mm, axis_tilt_deg; /**< the axis against the calibrated one */
    uint32_t worst_view;                 /**< the view with the largest residual */
    double worst_rms_mm;
    int failed_view;      /**< -1, or a view that does not match the one before it (or
                               the first view of a second pass that matches nothing) */
    int failed_against;   /**< the view it was compared with (-1: the first pass) */
    uint32_t arcs_held;   /**< pairs sharing no side (only a top) cut the views into arcs whose
                               turns against each other no pair sees: the arcs (but the first)
                               held to the table's angles against the first */
    uint32_t apart_pairs; /**< neighbouring views that share no surface to compare (two
                               views half a turn apart): no failure, the table's angle */
    int apart_view, apart_against; /**< the first such pair, or -1 */
    double failed_share;           /**< the share of their overlap that coupled */
    double failed_colour;          /**< > 0: they couple, but their paint misses by this share of
                                        a full miss (the object slid along its faces) */
    char refused[160];             /**< why a solved adjustment was not accepted ("" when it was) */
    double second_turned_deg;      /**< two passes: how far the object was turned between them */
    double second_share;           /**< the share of the second pass's points the search paired */
    uint32_t second_coupled;       /**< pairs of the final refinement against the first pass */
    double second_rms_mm;          /**< and their residual */
    uint32_t turns_from_table;     /**< views whose turn the geometry does not fix (reg_view) */
    uint32_t turns_little_shared;  /**< of them, those sharing too little surface */
    uint32_t turns_by_paint;       /**< of them, those turned by their paint */
    int axis_from_calibration;     /**< 1: the pairs do not see the axis's place: calibrated kept */
    int axis_unpaid;               /**< 1: kept so because moving it gained the pairs no more than
                                        their own errors explain (reg.c) */
    double axis_f;                 /**< what moving it gained, as an F value (reg.c) */
    int views_alike; /**< 1: each view looked like its neighbour as they stood (the object's
                          symmetry matches the table's step): the calibrated axis kept */
    int moved_view;  /**< -1, or the first view after the object moved on the table
                          (one pass): from it, moved_views views were placed freely */
    uint32_t moved_views;
    double moved_mm, moved_deg; /**< how far the object had moved, and turned */
    uint32_t few_samples;       /**< > 0: every view had fewer than REG_MIN_VIEW_SAMPLES valid
                                     samples, the fullest this many: nothing solved, no pair failed */
    int moved_by_colour; /**< the directions its shape left free, which its paint fixed (1 or 2;
                              0: its shape alone placed it) */
    int moved_unfixed;   /**< 1: failed_view's views fit the others only up to a slide
                              neither shape nor colour fixes */
};

/** A view with fewer valid samples than this holds too little to register by. When every view
 *  has fewer (the object small in the camera's image), the table's angles and the calibrated
 *  axis are kept (reg_report.few_samples); one among fuller views is a view of nothing, and a
 *  pair with it that overlaps and does not couple fails. */
#define REG_MIN_VIEW_SAMPLES 200u

#define REG_PARAMS (REG_MAX_VIEWS + 4u) /* every angle, two shifts, two tilts */
#define REG_EDGES REG_MAX_VIEWS         /* a ring: one edge per view */

/** One kept pixel of a view, in its camera frame. */
struct reg_cell {
    float xyz[3];
    float normal[3];
    uint8_t rgb[3];
    uint8_t valid;
    int16_t hue[2]; /* the mean of its pixels' hues x 32767 (reg_priv.h); REG_NO_HUE: too dark,
                       with REG_UNCOLOURED: no colour at all */
};
_Static_assert(sizeof(struct reg_cell) == 32, "cell layout");

/** What the pairs of one edge (both directions) gave in the last pass. */
struct reg_edge_stats {
    uint32_t overlap, coupled;
    uint32_t side_overlap, side_coupled; /**< of them, on surfaces facing sideways (reg.c) */
    double sq, trunc_sq; /**< squared residuals of coupled pairs; truncated over the overlap */
    /** How much of a turn about the axis the pair's coupled samples see: the sums of
     *  (n . (d x (p - a)))^2 and |d x (p - a)|^2, the motion across the surface and the whole
     *  motion of a turn (their ratio is 0 on a surface of revolution about the axis, about 0.5
     *  on a box); a view's are those of its pairs. */
    double turn_seen, turn_whole;
    double area_mm2; /**< the surface the coupled samples stand for (a stride's square each) */
    /** The coupled samples' normals along the table (the object frame's x and y, the same
     *  frame both ways): the sums of nx^2, nx ny, ny^2. A slide along the table in a direction
     *  none of them has moves no residual (reg_breaks.c). */
    double slide[3];
};

/** A registration: every view's samples and the joint solution, in one place (about
 *  REG_MAX_CELLS x 28 bytes). Its owner declares it static (a job, a test) and passes it to
 *  every call; two of them are two independent registrations. The fields are reg.c's. */
struct reg_ctx {
    struct reg_cell cells[REG_MAX_CELLS];
    double normal_a[REG_PARAMS * REG_PARAMS], normal_b[REG_PARAMS], step_x[REG_PARAMS];
    struct reg_params p;
    struct scan_calib calib;
    uint32_t views, passes, per_pass, stride, gw, gh;
    int32_t reported_mdeg[REG_MAX_VIEWS];
    uint8_t present[REG_MAX_VIEWS];
    uint32_t valid_cells[REG_MAX_VIEWS];  /**< each view's valid samples */
    double theta[REG_MAX_VIEWS];          /**< radians */
    double shift_seen[2], shift_whole[2]; /**< as reg_edge_stats' turn, for a shift of the axis
                                               across it, over every pair */
    int axis_from_calib;                  /**< the pairs do not see the axis: calibrated kept */
    int views_alike;                      /**< reg_views_alike: the axis held to the calibrated */
    uint32_t few_samples;                 /**< as reg_report's: the table's angles kept */
    uint8_t from_table[REG_MAX_VIEWS];    /**< the turn kept at the table's angle */
    uint8_t little_shared[REG_MAX_VIEWS]; /**< why: too little surface shared (reg.c) */
    uint8_t by_paint[REG_MAX_VIEWS];      /**< of those, turned where its paint agrees */
    int axis_held;                        /**< 1: solving with the axis held where calibrated */
    vec3 a, d;                            /**< the axis */
    int use_solution;                     /**< poses from theta, a, d rather than the turntable's */
    uint32_t edges, edge_from[REG_EDGES], edge_to[REG_EDGES];
    struct reg_edge_stats stats[REG_EDGES];
    /** The views placed through first_from_second (1): the second pass's, or those the object
     *  moved for (a slip cuts the ring of views in two arcs; the one without view 0 is placed
     *  freely, as a second pass is). */
    uint8_t group[REG_MAX_VIEWS];
    uint8_t cut_after[REG_MAX_VIEWS]; /**< the pair (v, v + 1) does not match: not an edge */
    uint8_t quiet_break_after[REG_MAX_VIEWS]; /**< the pair (v, v + 1) matches in shape, not
                                                    in colour, or shares no surface (reg.c,
                                                  find_quiet_breaks) */
    int second_aligned;                       /**< the group-1 views go through first_from_second */
    double placed_share[3]; /**< how well the last placement's pairs held a shift, weakest
                                 first (lsq_rigid_shift_axes) ... */
    vec3 placed_axis[3];    /**< ... along these directions (group 0's object frame) */
    int placed_by_colour;   /**< the directions the shape left free, the colours placed (0: none) */
    struct frame_xform first_from_second;
    struct frame_xform first_pose[REG_MAX_VIEWS], first_cam[REG_MAX_VIEWS]; /* refinement's */
    struct align_ctx align; /**< the second pass found in the first */
};

/** Forget every view and size the samples for @p views views of @p width x @p height in
 *  @p passes passes (1, or 2: the object laid another way for the second half of the views,
 *  which is found in the first without a starting pose, align.h): the stride grows beyond
 *  params->sample_stride until they fit REG_MAX_CELLS.
 *  @retval 0 @retval -E2BIG more views than REG_MAX_VIEWS, or not passes x views per pass */
int reg_begin(struct reg_ctx *r, const struct reg_params *params, const struct scan_calib *calib,
              uint32_t views, uint32_t passes, uint32_t width, uint32_t height);

/** Keep samples of view @p index (camera frame) taken at the reported @p angle_mdeg.
 *  @param rgb  the view's colour, 3 bytes a pixel
 *  @param confidence  its confidence a pixel: a negative one has no colour (colour.h's
 *         COLOUR_NO_ESTIMATE), left out of a sample's colour; NULL: every pixel has one
 *  @retval 0 @retval -EINVAL index or size outside what reg_begin was given */
int reg_add_view(struct reg_ctx *r, uint32_t index, int32_t angle_mdeg,
                 const struct decode_maps *maps, const struct tri_range *range, const uint8_t *rgb,
                 const float *confidence);

/** Register every added view jointly. @param report out
 *  @retval 0 (a failed match is reported in report->failed_view, not as an error) */
int reg_solve(struct reg_ctx *r, struct reg_report *report);

/** View @p index after reg_solve: its pose (camera frame to object frame) and numbers.
 *  @retval 0 @retval -EINVAL not added */
int reg_view_pose(struct reg_ctx *r, uint32_t index, struct frame_xform *obj_from_cam,
                  struct reg_view *view);

/** Every valid kept sample of every added view (every stride-th pixel), at its view's pose
 *  after reg_solve (reg_view_pose): handed to @p each in the object frame, mm. */
void reg_each_point(struct reg_ctx *r, void (*each)(void *priv, vec3 p_obj), void *priv);

#endif
