/* SPDX-License-Identifier: MIT */
/* rch_rapid.h - the ABB RAPID reader: every joint target and robtarget
 * literal of a module, where it is and what it holds (prefix rch_rapid_).
 *
 * A tokenizer that knows comments ('!' to the end of the line), strings
 * ("..." with "" for a quote), statements spanning lines and several per
 * line, and aggregates [...]. Each top-level aggregate is classified by its
 * context:
 *  - a declaration [LOCAL|TASK] VAR|PERS|CONST TYPE NAME [{dims}] := [...]:
 *    the declared type decides (jointtarget, robtarget, arrays of them);
 *    another type is not a target and is skipped;
 *  - an assignment NAME := [...] or NAME{i} := [...]: the type of NAME as
 *    declared anywhere in the module; a target-shaped value assigned to a
 *    name not declared here is an error (its type cannot be told);
 *  - anywhere else (an instruction's argument, MoveAbsJ [[...]], MoveL
 *    [[...]], \ToPoint:=[...]): the shape decides, [[6],[6]] a jointtarget,
 *    [[3],[4],[4],[6]] a robtarget.
 * Declared types: jointtarget, robtarget and an ALIAS of them (ALIAS
 * robtarget mypos;) are targets; a value of a RECORD type with a target
 * field (directly or in a nested record) is listed with an error naming the
 * field (rcal does not rewrite targets inside records).
 * Uses: each statement's instruction is read with ABB's argument order
 * (RAPID reference: the target arguments and the Tool by position, \WObj:=
 * by name): MoveL/J/C, MoveAbsJ, their DO/AO/GO/Sync variants, TriggL/J/C,
 * TriggLIOs/TriggJIOs, SearchL/C, ArcL/C (and their Start/End), ContactL,
 * MoveExtJ, SearchExtJ and the function CalcJointT. A target named (or
 * written inline) in one of their target arguments gets that instruction's
 * tool and work object, and the frames the module declares for them
 * (literal tooldata, wobjdata). A robtarget passed to any other procedure
 * (a user PROC, an instruction rcal does not know, a late-bound call),
 * returned, or assigned to what is not a robtarget of the module has an
 * unknown use; one assigned to a robtarget of the module takes that one's
 * uses. use_error is set for a robtarget whose tool and work object cannot
 * be told: only unknown uses, two uses with different tools or work
 * objects, a tool argument that is not a name (or names data of another
 * type). A target literal whose shape is wrong or whose numbers are not literal
 * numbers is listed with its error (the caller names it and refuses).
 * Nothing here computes; the caller rewrites the numbers' bytes
 * (num_off/num_len) and copies every other byte.
 *
 * Lines end at LF, CRLF or a lone CR (old Mac files), each counted for
 * line:col; a UTF-8 byte-order mark at the start is skipped (offsets stay
 * offsets into text, so a caller that copies the text keeps both).
 *
 * Host side: heap, no file I/O. Errors (a string not closed, a NUL byte, an
 * aggregate not closed, too large an input): -1 with rch_diag set. */
#ifndef RCH_RAPID_H
#define RCH_RAPID_H

#include <stddef.h>

#include "rch_diag.h"

#define RCH_RAPID_MAX_BYTES (16u << 20) /* a larger module is refused */
#define RCH_RAPID_NUMS 11               /* numbers a target carries that may change */

typedef enum rch_rapid_kind {
    RCH_RAPID_JOINTTARGET = 1, /* [[q1..q6],[e1..e6]]: the six robot axes (deg) may change */
    RCH_RAPID_ROBTARGET = 2    /* [[x,y,z],[q1..q4],[cf1,cf4,cf6,cfx],[e1..e6]]: trans, rot, robconf */
} rch_rapid_kind;

typedef enum rch_rapid_context {
    RCH_RAPID_DECLARATION = 1,
    RCH_RAPID_ASSIGNMENT = 2,
    RCH_RAPID_INLINE = 3 /* an instruction's argument or another expression */
} rch_rapid_context;

typedef struct rch_rapid_target {
    rch_rapid_kind kind;
    rch_rapid_context context;
    unsigned line, col;            /* 1-based, of the literal's '[' */
    size_t off, end;               /* the literal: text[off..end) */
    unsigned n;                    /* numbers below: 6 (jointtarget) or 11 (robtarget); 0 with an error */
    size_t num_off[RCH_RAPID_NUMS]; /* each number's bytes, its sign included */
    size_t num_len[RCH_RAPID_NUMS];
    double val[RCH_RAPID_NUMS];    /* robax (deg) | x, y, z (mm), q1..q4, cf1, cf4, cf6, cfx */
    unsigned num_line[RCH_RAPID_NUMS], num_col[RCH_RAPID_NUMS];
    char name[48];                 /* the declared or assigned name; "" inline */
    char tool[48], wobj[48];       /* of the first motion instruction that uses it ("" wobj: wobj0); "" tool
                                      when none does */
    char use_instr[24];            /* that instruction's name */
    unsigned use_line;             /* its line */
    int tool_declared;             /* that tool is declared in the module with a literal tooldata: */
    int tool_robhold;              /*   its robhold (1 TRUE: held by the robot) */
    double tool_frame[7];          /*   its tframe: trans (mm, in tool0's frame), rot (q1..q4) */
    int wobj_declared;             /* that work object is declared in the module with a literal wobjdata: */
    int wobj_robhold, wobj_ufprog; /*   robhold (1: held by the robot), ufprog (0: a moving user frame) */
    char wobj_ufmec[48];           /*   ufmec */
    double wobj_uframe[7], wobj_oframe[7]; /* uframe (in world), oframe (in uframe): trans (mm), rot */
    char use_error[400];           /* not empty: its tool and work object cannot be told (robtargets only) */
    unsigned extax_used;           /* robtargets: 1 + the first external axis (eax_a ..) whose value is not 9E9
                                      (unused: a track, a positioner or another axis in use), 0: none */
    double extax_val;              /*   its value (NaN: not a literal number) */
    unsigned extax_line, extax_col; /*  and where it stands */
    char error[256];               /* not empty: the literal cannot be read (shape, not a number) */
} rch_rapid_target;

typedef struct rch_rapid_targets {
    rch_rapid_target *t; /* (n) in the order of the text */
    size_t n, cap;
} rch_rapid_targets;

/* Every target literal of text[0..len) (named name in messages) into *out
 * (zero it first; rch_rapid_free after). 0, or -1 with d set and *out
 * empty. */
int rch_rapid_scan(rch_rapid_targets *out, const char *text, size_t len, const char *name, rch_diag *d);
void rch_rapid_free(rch_rapid_targets *ts);

/* The target kind's name, "jointtarget" or "robtarget". */
const char *rch_rapid_kind_name(rch_rapid_kind k);
/* "declaration", "assignment" or "inline". */
const char *rch_rapid_context_name(rch_rapid_context c);

#endif
