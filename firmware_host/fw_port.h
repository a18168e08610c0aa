/* SPDX-License-Identifier: MIT */
/* fw_port.h - what a firmware build of the rcal core redirects.
 *
 * Force-included (-include fw_port.h) when the core is compiled for the
 * microcontroller: contract violations go to the firmware's fault handler
 * instead of the C library's assert (which would pull in fprintf). The
 * handler is defined by the firmware (fw_example.c here). It also sizes the
 * compensation stream for firmware (RC_COMP_STREAM_OWN_MODELS).
 */
#ifndef FW_PORT_H
#define FW_PORT_H

void fw_fault(const char *file, int line);
#define RC_ASSERT(cond) ((cond) ? (void)0 : fw_fault(__FILE__, __LINE__))

/* The firmware streams over compiled tables in flash only
 * (rc_comp_stream_init_kin): no room for compiled models in the stream. */
#define RC_COMP_STREAM_OWN_MODELS 0

#endif
