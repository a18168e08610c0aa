/* SPDX-License-Identifier: MIT */
/* rc_model.h - robot model, forward kinematics and the cable-length measurement.
 *
 * What: a six-joint serial arm in standard Denavit-Hartenberg form,
 *   T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i),  theta_i = q_i + theta_off_i,
 * a cable-encoder outlet e in the base frame, and optional model extensions
 * ("effects") for what pure geometry misses. Length-side effects (offset,
 * scale, drift, group offsets, cable sag, length nonlinearity and periodic)
 * change the predicted cable length only, never the flange pose (rc_fk,
 * rc_kin). The predicted cable length is
 *   l(q) = |p(q) - e| + (length-side effects),
 * p(q) being the translation of T_1...T_6 (the flange point).
 *
 * Parameter vector x (n_params), one storage order everywhere:
 *   x[4*i + 0] a_i      (mm)     joint i = 0..5
 *   x[4*i + 1] d_i      (mm)
 *   x[4*i + 2] alpha_i  (rad)
 *   x[4*i + 3] theta_i  (rad)    offset added to the joint reading q_i
 *   x[24..26]  e        (mm)     encoder outlet in the base frame
 *   x[27..]    effect parameters, in the order the effects were added.
 * Matrices are row-major; 3x3 rotations as double[9].
 *
 * Depends on: libm only. Memory: all structs are caller-owned, fixed size.
 * Thread safety: functions are reentrant; a model may be shared read-only.
 * Errors: rc_status codes; contract violations to RC_ASSERT.
 */
#ifndef RC_MODEL_H
#define RC_MODEL_H

#include <stddef.h>
#include <stdint.h>

#include "rc_config.h"
#include "rc_status.h"

#define RC_P_A(i) (4 * (i) + 0)
#define RC_P_D(i) (4 * (i) + 1)
#define RC_P_ALPHA(i) (4 * (i) + 2)
#define RC_P_THETA(i) (4 * (i) + 3)
#define RC_P_ENC RC_N_DH

/* Model extensions, one list: RC_EFFECTS gives the kinds (the enum), their
 * descriptions (rc_effect_describe) and, in rc_model.c, each length-side
 * kind's one value-and-gradient function (eff_<KIND>). Joint-side effects
 * change the joint angle seen by the geometry; length-side effects add to
 * the predicted cable length. Adding a kind: one line here (at the end: the
 * numbers are stable), its function in rc_model.c (length side) or its part
 * of the chain (joint, point, geometry or sensor side).
 * X(ID, name, count, side, arg, unit class, nuisance, user, unit text, limit,
 *   suffixes, index prefix, index base) as in rc_effect_desc below. The kinds:
 *  none:
 *  length_offset:  l += b;                         1 param, mm
 *  joint_compliance:  theta_j += k * tau_j(q);       1 param, rad per m of lever
 *  joint_periodic:  theta_j += s1 sin q + c1 cos q + s2 sin 2q + c2 cos 2q; 4 params, rad
 *  time_drift:  l += d1 t + d2 t^2 (+ d3 t^3 + d4 t^4), t in [0,1] acquisition order;
 *      count params (1..4; 0: 3), mm
 *  group_offset:  l += g_k for samples of group k; count params, mm
 *  length_scale:  l *= (1 + s) (encoder scale);   1 param, unitless
 *  tool_offset:  measured point = flange + R6 (tx, ty, tz): where the cable
 *      is attached, in the flange frame; 3 params, mm
 *  cable_sag:  l += c h^2 L: the extra length of a light cable hanging
 *      between outlet and attachment point; 1 param, mm per m^3
 *  length_nonlinearity:  l += n2 (lam - c)^2 + n3 (lam - c)^3, the length sensor's
 *      deviation from linear; 2 params, mm per m^2 and mm per m^3
 *  length_periodic:  l += s sin(2 pi L / P) + c cos(2 pi L / P), L the chord: the
 *      length sensor's error once per drum turn (an eccentric drum);
 *      3 params s, c (mm) and the period P (mm, the drum's
 *      circumference; nonlinear, |P| < 1e-9 mm: no effect)
 *  outlet:  another place of the encoder: samples with rc_sample.outlet == k
 *      (the effect's `joint` field, 1..RC_MAX_OUTLETS-1) are measured from
 *      this outlet instead of e; 3 params (x, y, z) mm in the base frame
 *  axis_tilt:  Hayati's beta of DH row j (joint): frame j+1 turned about its own y
 *      axis after Rx(alpha): T_j = Rz(theta) Tz(d) Tx(a) Rx(alpha) Ry(beta).
 *      The tilt of a joint axis against a nominally parallel previous one,
 *      which standard DH can only express with d of metres; 1 param, rad
 *  tracker_position:  a position sensor's frame (laser tracker): the translation T of
 *      p_tracker = R p_base + T; 3 params (x, y, z) mm (lib/rc_sensor.h)
 *  tracker_rotation:  its rotation R = exp([w]x), w the rotation vector; 3 params, rad
 *  tracker_targets:  the targets the tracker sees on the tool: a sample with rc_sample.target
 *      == k sees flange + R6 (x_k, y_k, z_k); 3 params per target (count =
 *      3 x targets, at most RC_MAX_TARGETS), mm in the flange frame
 *  outlet_offset:  l += b_k for samples with rc_sample.outlet == k: each outlet's own zero
 *      (a display re-zeroed at one outlet, a different cable hook); count
 *      params, one per outlet (0: 1 + the largest RC_EFF_OUTLET number), mm
 *  outlet_scale:  l *= 1 + s_k for samples from outlet k (each encoder's own scale, or
 *      one cable stretched differently); count params as OUTLET_OFFSET
 *  tracker_scale:  the tracker's length scale: p_tracker = (1 + s) (R p_base + T), e.g.
 *      a wrong air temperature in its refractive index; 1 param, unitless
 *  cable_points:  the points of a tool plate the cable is hooked on in turn: a length
 *      sample with rc_sample.target == k is measured to flange + R6 (x_k, y_k,
 *      z_k) instead of the flange centre or RC_EFF_TOOL_OFFSET's point; 3
 *      params per point (count = 3 x points, at most RC_MAX_TARGETS), mm in
 *      the flange frame. Points apart on the plate make the flange's
 *      orientation visible to the cable, as targets make it to a tracker
 *  touch_tip:  the touch probe's point (or a hard tool tip) in the flange frame: a
 *      plane sample (RC_SENSOR_PLANE) sees flange + R6 (x, y, z); 3 params, mm
 *  plane_normals:  plate k's unit normal n_k = rc_plane_normal(theta_k, phi_k); 2
 *      params per plate (count = 2 x plates), rad
 *  plane_offsets:  plate k's distance d_k from the base origin along n_k; a plane
 *      sample of plate k predicts n_k . p - d_k (measured: 0); 1 param per
 *      plate, mm
 */
#define RC_EFFECTS(X) \
    X(NONE, "none", 0, RC_SIDE_LENGTH, RC_EFF_ARG_NONE, 2, 0, 0, "", 0.0, "", "", 0) \
    X(LENGTH_OFFSET, "length_offset", 1, RC_SIDE_LENGTH, RC_EFF_ARG_NONE, 0, 0, 1, "mm", 1000.0, "", "", 0) \
    X(JOINT_COMPLIANCE, "joint_compliance", 1, RC_SIDE_JOINT, RC_EFF_ARG_JOINT, 2, 0, 1, "rad/m", 0.1, "", "", 0) \
    X(JOINT_PERIODIC, "joint_periodic", 4, RC_SIDE_JOINT, RC_EFF_ARG_JOINT, 1, 0, 1, "rad", 0.2, "s1|c1|s2|c2", "", 0) \
    X(TIME_DRIFT, "time_drift", 0, RC_SIDE_LENGTH, RC_EFF_ARG_COUNT, 0, 1, 1, "mm", 1000.0, "", "d", 1) \
    X(GROUP_OFFSET, "group_offset", 0, RC_SIDE_LENGTH, RC_EFF_ARG_COUNT, 0, 1, 0, "mm", 1000.0, "", "g", 0) \
    X(LENGTH_SCALE, "length_scale", 1, RC_SIDE_LENGTH, RC_EFF_ARG_NONE, 2, 0, 1, "", 0.1, "", "", 0) \
    X(TOOL_OFFSET, "tool_offset", 3, RC_SIDE_POINT, RC_EFF_ARG_NONE, 0, 0, 1, "mm", 1000.0, "x|y|z", "", 0) \
    X(CABLE_SAG, "cable_sag", 1, RC_SIDE_LENGTH, RC_EFF_ARG_NONE, 2, 0, 1, "mm/m^3", 1000.0, "", "", 0) \
    X(LENGTH_NONLIN, "length_nonlinearity", 2, RC_SIDE_LENGTH, RC_EFF_ARG_NONE, 2, 0, 1, "mm/m^2, mm/m^3", 1000.0, "n2|n3", "", 0) \
    X(LENGTH_PERIODIC, "length_periodic", 3, RC_SIDE_LENGTH, RC_EFF_ARG_PERIOD, 0, 0, 1, "mm", 1000.0, "s|c|period", "", 0) \
    X(OUTLET, "outlet", 3, RC_SIDE_OUTLET, RC_EFF_ARG_OUTLET, 0, 0, 0, "mm", 1e5, "x|y|z", "", 0) \
    X(AXIS_TILT, "axis_tilt", 1, RC_SIDE_GEOMETRY, RC_EFF_ARG_JOINT, 1, 0, 1, "rad", 0.1, "", "", 0) \
    X(TRACKER_POSITION, "tracker_position", 3, RC_SIDE_SENSOR, RC_EFF_ARG_NONE, 0, 0, 0, "mm", 1e5, "x|y|z", "", 0) \
    X(TRACKER_ROTATION, "tracker_rotation", 3, RC_SIDE_SENSOR, RC_EFF_ARG_NONE, 1, 0, 0, "rad", 7.0, "x|y|z", "", 0) \
    X(TRACKER_TARGETS, "tracker_targets", 0, RC_SIDE_SENSOR, RC_EFF_ARG_COUNT, 0, 0, 0, "mm", 1e4, "x|y|z", "", 0) \
    X(OUTLET_OFFSET, "outlet_offset", 0, RC_SIDE_LENGTH, RC_EFF_ARG_COUNT, 0, 0, 1, "mm", 1000.0, "", "o", 0) \
    X(OUTLET_SCALE, "outlet_scale", 0, RC_SIDE_LENGTH, RC_EFF_ARG_COUNT, 2, 0, 1, "", 0.001, "", "o", 0) \
    X(TRACKER_SCALE, "tracker_scale", 1, RC_SIDE_SENSOR, RC_EFF_ARG_NONE, 2, 0, 1, "", 3e-4, "", "", 0) \
    X(CABLE_POINTS, "cable_points", 0, RC_SIDE_POINT, RC_EFF_ARG_COUNT, 0, 0, 0, "mm", 1e4, "x|y|z", "", 0) \
    X(TOUCH_TIP, "touch_tip", 3, RC_SIDE_SENSOR, RC_EFF_ARG_NONE, 0, 0, 0, "mm", 1e4, "x|y|z", "", 0) \
    X(PLANE_NORMALS, "plane_normals", 0, RC_SIDE_SENSOR, RC_EFF_ARG_COUNT, 1, 0, 0, "rad", 7.0, "theta|phi", "p", 0) \
    X(PLANE_OFFSETS, "plane_offsets", 0, RC_SIDE_SENSOR, RC_EFF_ARG_COUNT, 0, 0, 0, "mm", 1e5, "", "p", 0)

#define RC_EFF_ENUM_(id, ...) RC_EFF_##id,
typedef enum rc_effect_kind { RC_EFFECTS(RC_EFF_ENUM_) RC_EFF_COUNT_ } rc_effect_kind;
#undef RC_EFF_ENUM_

/* Last effect kind (for range checks of stored kinds). */
#define RC_EFF_LAST (RC_EFF_COUNT_ - 1)

/* Targets a position data set may use (rc_sample.target, RC_EFF_TRACKER_TARGETS). */
#define RC_MAX_TARGETS 16

/* Outlets a data set may use (outlet 0 is e, the others RC_EFF_OUTLET). */
#define RC_MAX_OUTLETS 16

/* The one description of every effect kind: what sizes, names, units and
 * limits are expanded from (rc_effect_describe), so that an effect is
 * defined once: its row here, its formula in rc_meas (length, outlet and
 * point side) or rc_model_theta (joint side), nothing else. */
typedef enum {
    RC_EFF_ARG_NONE = 0,   /* added with no argument */
    RC_EFF_ARG_JOINT = 1,  /* the joint it acts on (0..5; the file's "joint" 1..6) */
    RC_EFF_ARG_COUNT = 2,  /* its parameter count (drift degree, number of groups) */
    RC_EFF_ARG_PERIOD = 3, /* a start value for its period, set by the caller */
    RC_EFF_ARG_OUTLET = 4  /* the outlet number (1.., the file's "outlet") */
} rc_effect_arg;

typedef enum {
    RC_SIDE_LENGTH = 0, /* adds to the predicted length; never moves the flange */
    RC_SIDE_JOINT = 1,  /* changes a joint angle the geometry sees: moves the flange */
    RC_SIDE_POINT = 2,  /* moves the measured point in the flange frame (not the flange) */
    RC_SIDE_OUTLET = 3, /* where a sample's length is measured from */
    RC_SIDE_GEOMETRY = 4, /* part of the chain's geometry (a DH row's extra parameter): moves the flange */
    RC_SIDE_SENSOR = 5   /* where a non-length sensor sees the robot from (tracker frame, targets):
                            moves nothing, no prior */
} rc_effect_side;

typedef struct rc_effect_desc {
    uint8_t kind;             /* rc_effect_kind */
    const char *name;         /* machine name: the model file's "kind" and --effects' */
    uint8_t count;            /* parameters; 0: given when added (RC_EFF_ARG_COUNT) */
    uint8_t side;             /* rc_effect_side */
    uint8_t arg;              /* rc_effect_arg */
    uint8_t unit;             /* unit class of its parameters, as rc_param_unit: 0 mm, 1 rad, 2 other */
    uint8_t nuisance;         /* 1: describes one acquisition, not the robot: predicts nothing at a new pose */
    uint8_t user;             /* 1: may be named in `rcal calibrate --effects` */
    const char *unit_text;    /* the units in words, for messages */
    double limit;             /* largest plausible |parameter| (the file's SI units): beyond, a typo */
    const char *suffixes;     /* parameter name suffixes, '|'-separated ("x|y|z"), or "" */
    const char *index_prefix; /* with no suffixes and count > 1: name.<prefix><index + index_base>; with
                                 suffixes and count above their number: name.<prefix><repeat>.<suffix> */
    uint8_t index_base;
} rc_effect_desc;

/* The description of kind, NULL when kind is not an effect kind. */
const rc_effect_desc *rc_effect_describe(unsigned kind);
/* The kind named name (rc_effect_desc.name), or -1. */
int rc_effect_by_name(const char *name);

/* RC_EFF_CABLE_SAG. A light cable of weight w per length under tension T
 * hangs below its chord; its arc exceeds the chord by about
 *   w^2 h^2 L / (24 T^2)
 * (parabolic approximation of the catenary, small sag), h the horizontal
 * span and L the chord between outlet e and the measured point p. Gravity
 * is taken along -z of the robot base frame, so h is the span in the base
 * x-y plane: h^2 = (px - ex)^2 + (py - ey)^2. The parameter is
 * c = 1000 w^2 / (24 T^2) in mm of extra length per m^3 of h^2 L (h, L in
 * metres); the model is linear in c. */

/* RC_EFF_LENGTH_NONLIN. The sensor's reading beyond linear in the cable
 * length: quadratic and cubic terms in lam = L / 1000 (the chord in metres)
 * about the fixed centre RC_LENGTH_NONLIN_CENTRE_M; the linear part and the
 * offset are RC_EFF_LENGTH_SCALE and RC_EFF_LENGTH_OFFSET. The centre only
 * conditions the parameters: about another centre the same curve differs by
 * a constant and a linear term. */
#define RC_LENGTH_NONLIN_CENTRE_M 0.5

typedef struct rc_effect {
    uint8_t kind;     /* rc_effect_kind */
    uint8_t joint;    /* 0..5 for joint-side effects, the outlet number for RC_EFF_OUTLET, else 0 */
    uint16_t first;   /* index of its first parameter in x */
    uint16_t count;   /* number of parameters */
    /* Frozen reference geometry (DH rows of joints 1..4: a, d, alpha, theta)
     * for the gravity lever of RC_EFF_JOINT_COMPLIANCE, copied when the effect
     * is added so that the lever depends on q only. */
    double ref_dh[4][4];
} rc_effect;

typedef struct rc_model {
    uint16_t n_params;                 /* 27 + sum of effect counts */
    uint16_t n_effects;
    rc_effect effects[RC_MAX_EFFECTS];
    double x[RC_MAX_PARAMS];           /* (n_params) see the storage order above */
    double q_min_rad[RC_NJ];           /* joint limits */
    double q_max_rad[RC_NJ];
} rc_model;

/* What a sample measured (rc_sample.sensor): one scalar residual row each,
 * in one list. RC_SENSORS gives the kinds (the enum), their units
 * (rc_sensor_unit) and each one's hook (lib/rc_sensor.h: its value, the
 * point it sees and d value / d point, its own parameters' derivatives; the
 * chain's part is rc_model.c's, the same for every sensor). A cable length
 * is the chain's own (no hook). A tracker position is three samples, its x,
 * y and z components in the tracker's frame. Adding a sensor: one line here
 * (at the end: the numbers are stable), its hook in a file of its own, its
 * effects in RC_EFFECTS (side RC_SIDE_SENSOR).
 * X(ID, name, unit, hook) */
#define RC_SENSORS(X)                                                   \
    X(LENGTH, "length", "mm", rc_sensor_none)                          \
    X(TRACKER_X, "tracker_x", "mm", rc_sensor_tracker)                 \
    X(TRACKER_Y, "tracker_y", "mm", rc_sensor_tracker)                 \
    X(TRACKER_Z, "tracker_z", "mm", rc_sensor_tracker)                 \
    X(PLANE, "plane", "mm", rc_sensor_plane)

#define RC_SENSOR_ENUM_(id, name, unit, hook) RC_SENSOR_##id,
typedef enum rc_sensor_kind { RC_SENSORS(RC_SENSOR_ENUM_) RC_SENSOR_COUNT_ } rc_sensor_kind;
#undef RC_SENSOR_ENUM_

/* The unit of a sensor's measured value (rc_sample.sensor): "mm" for a
 * length and a tracker coordinate; "?" for a kind the model does not know. */
const char *rc_sensor_unit(unsigned sensor);
/* The name of a sensor kind ("length", ...), "unknown" for another number. */
const char *rc_sensor_name(unsigned sensor);

/* A plate's unit normal n (3) from its angles (RC_EFF_PLANE_NORMALS):
 * n = cos(theta) P + sin(theta) (cos(phi) E1 + sin(phi) E2), P = (1, 2, 3) /
 * sqrt(14), E1 = (-2, 1, 0) / sqrt(5), E2 = P x E1: polar angles about a pole
 * no horizontal, vertical or 45-degree plate faces (P is 37 deg from z, 58
 * from y, 74 from x), so phi is well determined for the plates of a cell.
 * dn_dtheta, dn_dphi (3 each) or NULL: the derivatives. */
void rc_plane_normal(double n[3], double dn_dtheta[3], double dn_dphi[3], double theta, double phi);
/* The angles of the unit normal n (3): theta in [0, pi], phi in (-pi, pi]
 * (singular at n = +-P only). A plate's normal points out of its face, to
 * the side the probe comes from (tools/host/fit/rch_sensor_touch.c), so a
 * gauge block's top is at +height. */
void rc_plane_angles(double *theta, double *phi, const double n[3]);

/* One measurement: joint readings, cable length and its context. Zero-
 * initialise it (memset, calloc or = {0}) before filling the fields: a zero
 * sensor, target and outlet is a cable length from the first outlet, and a
 * sensor kind the model does not know makes rc_meas return RC_ERR_ARG. */
typedef struct rc_sample {
    double q_rad[RC_NJ]; /* (6) joint readings */
    double value;        /* the measured value (mm): cable length, or the tracker coordinate */
    double t;            /* acquisition order scaled to [0, 1] */
    uint16_t group;      /* set-up group (consecutive samples sharing a set-up) */
    uint8_t outlet;      /* the encoder outlet it was measured from: 0 = e, k = the RC_EFF_OUTLET effect
                            with joint k (a sample whose outlet the model lacks has no length: RC_ERR_ARG) */
    uint8_t sensor;      /* rc_sensor_kind: what len_mm is */
    uint8_t target;      /* tracker samples: the target seen (its three parameters in RC_EFF_TRACKER_TARGETS);
                            length samples of a model with RC_EFF_CABLE_POINTS: the point the cable is on */
    double weight;       /* the row's weight in a fit: its residual and derivatives times this (a stated sd's
                            ratio, sigma_ref / sigma_i); 0: 1 (rc_sample_weight). Read by the solver's passes,
                            not by rc_meas or rc_eval (a value and its error stay physical) */
} rc_sample;

/* The weight of sample s in a fit (rc_sample.weight, 0 read as 1). */
static inline double rc_sample_weight(const rc_sample *s) { return s->weight > 0.0 ? s->weight : 1.0; }

/* Initialise a model from a DH table and an encoder position.
 * dh: (6 x 4) rows a_mm, d_mm, alpha_rad, theta_off_rad; enc_mm: (3).
 * Joint limits default to +-pi. */
rc_status rc_model_init(rc_model *m, const double dh[RC_NJ][4], const double enc_mm[3]);

/* Append an effect with zero-valued parameters. count is used only by
 * RC_EFF_GROUP_OFFSET (number of groups); joint only by joint-side effects.
 * RC_ERR_CAPACITY when RC_MAX_PARAMS or RC_MAX_EFFECTS would be exceeded. */
rc_status rc_model_add_effect(rc_model *m, rc_effect_kind kind, unsigned joint, unsigned count);

/* Wrap every DH angle (alpha_i, theta_i) into (-pi, pi]: the model is
 * unchanged (angles enter through sin and cos only). Angles beyond 1e6 rad
 * (a diverged solve) are left alone: reducing them would move them. */
void rc_model_wrap_angles(rc_model *m);

/* Short machine name of an effect kind ("length_offset", ...); never NULL. */
const char *rc_effect_name(rc_effect_kind kind);

/* Name of parameter k of model m into buf (e.g. "a2", "theta3", "ex",
 * "joint_periodic.j3.s1"); returns buf. */
const char *rc_param_name(char *buf, size_t buf_len, const rc_model *m, unsigned k);

/* The effect of m that parameter k belongs to, or NULL (the geometry and
 * the encoder, k < RC_N_BASE, or k beyond the model). */
const rc_effect *rc_param_effect(const rc_model *m, unsigned k);

/* Unit class of parameter k: 0 = mm, 1 = rad, 2 = other (rad/m, unitless). */
int rc_param_unit(const rc_model *m, unsigned k);

/* The effective joint angles theta_i = q_i + theta_off_i + joint-side effects.
 * theta_rad: (6). */
void rc_model_theta(double theta_rad[RC_NJ], const rc_model *m, const double q_rad[RC_NJ]);

/* Gravity lever of joint j (1 or 2, i.e. joints 2 and 3) in metres: the
 * moment arm about the joint axis of a point mass at the wrist centre, from
 * the frozen geometry ref_dh (4 x 4). Used by RC_EFF_JOINT_COMPLIANCE. */
double rc_gravity_lever_m(const double ref_dh[4][4], unsigned joint, const double q_rad[RC_NJ]);

/* Forward kinematics. pos_mm: (3) flange point (the tool point when the
 * model has RC_EFF_TOOL_OFFSET); rot: (3 x 3) flange
 * orientation or NULL. */
void rc_fk(double pos_mm[3], double rot[9], const rc_model *m, const double q_rad[RC_NJ]);

/* Forward kinematics with the geometric joint Jacobian.
 * jac: (6 x 6) row-major, rows 0..2 d(pos_mm)/d(q_rad), rows 3..5 angular
 * velocity per joint rate (rad/rad). Joint-side effects are included in the
 * chain rule. rot may be NULL. */
void rc_fk_jac(double pos_mm[3], double rot[9], double jac[36], const rc_model *m,
               const double q_rad[RC_NJ]);

/* Predicted value of one sample (its cable length, or for a tracker sample,
 * rc_sample.sensor, its coordinate: lib/rc_sensor.h) and, when jac is not
 * NULL, its analytic derivative with respect to every model parameter.
 * jac: (m->n_params). Returns RC_ERR_NUMERIC when the flange point
 * coincides with the encoder outlet (length derivative undefined).
 * Same as rc_meas_prepare + rc_meas_prepared(no tables): bit for bit what a
 * solver computes for the same model and sample. */
rc_status rc_meas(double *len_mm, double *jac, const rc_model *m, const rc_sample *s);

/* Many measurements of one model (a solver's pass over the data).
 * The joint angle is theta_i = q_i + theta_off_i; its sine and cosine come
 * from angle addition, sin(q + t) = sin q cos t + cos q sin t, so the
 * offsets' and alphas' sines are taken once per model (rc_meas_prep) and
 * the readings' once per data set (rc_qtrig_fill), never per pass. Joints with a
 * joint-side effect (compliance, periodic) take sin and cos of their full
 * angle directly. */

/* Sines and cosines of the joint readings of samples (n), as two tables:
 * sin_q (n x 6) and cos_q (n x 6), row k for samples[k]. */
void rc_qtrig_fill(double *sin_q, double *cos_q, const rc_sample *samples, size_t n);

/* What a model needs once per pass: sines and cosines of its DH angles and
 * where its effects are. Valid while the model is unchanged. */
typedef struct rc_meas_prep {
    double cos_off[RC_NJ], sin_off[RC_NJ];     /* (6) of theta_off_i */
    double cos_alpha[RC_NJ], sin_alpha[RC_NJ]; /* (6) of alpha_i */
    uint8_t joint_effect[RC_NJ];               /* nonzero: joint i has a joint-side effect */
    uint8_t has_joint_effect;                  /* any of joint_effect */
    int16_t tool;                              /* index of the tool offset in x, -1: none */
    int16_t points;                            /* index of RC_EFF_CABLE_POINTS in x, -1: none */
    uint8_t n_points;                          /* its points */
    double tilt_cm1[RC_NJ], tilt_s[RC_NJ];     /* (6) cos(beta) - 1 and sin(beta) of each row's axis tilt */
    int16_t tilt_at[RC_NJ];                    /* (6) index of row i's tilt in x, -1: none */
    uint8_t has_tilt;                          /* any row tilted */
} rc_meas_prep;

void rc_meas_prepare(rc_meas_prep *p, const rc_model *m);

/* The measured point (the flange point, the tool point with
 * RC_EFF_TOOL_OFFSET, or a length sample's cable point with
 * RC_EFF_CABLE_POINTS) of sample s as rc_meas_prepared sees it: pos_mm (3).
 * sin_q, cos_q as there. */
void rc_point_prepared(double pos_mm[3], const rc_model *m, const rc_meas_prep *p, const rc_sample *s,
                       const double *sin_q, const double *cos_q);

/* rc_meas with p = rc_meas_prepare(m) and the reading's sines and cosines
 * sin_q, cos_q (6 each, rc_qtrig_fill of s; both NULL: computed here).
 * The result does not depend on whether they are given. */
rc_status rc_meas_prepared(double *len_mm, double *jac, const rc_model *m, const rc_meas_prep *p,
                           const rc_sample *s, const double *sin_q, const double *cos_q);

#endif /* RC_MODEL_H */
