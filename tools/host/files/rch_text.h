/* SPDX-License-Identifier: MIT */
/* rch_text.h - the one UTF-8 check, the one XML/HTML escaper and the one
 * shell quoting of the host library: the JSON writer (rch_jw), the SVG
 * charts (rch_plot), the report (rch_report), the URDF export (rch_export)
 * and the next steps commands print all write text through these.
 *
 * Host side (prefix rch_). */
#ifndef RCH_TEXT_H
#define RCH_TEXT_H

#include <stddef.h>
#include <stdio.h>

/* Length of the well-formed UTF-8 sequence at s (1..4), or 0 when the bytes
 * there are not one: overlong forms, surrogates (U+D800..U+DFFF) and code
 * points above U+10FFFF are not well-formed. s must be NUL-terminated (a cut
 * sequence is not well-formed). */
size_t rch_utf8_len(const unsigned char *s);

/* Flags of rch_xml_piece / rch_xml_put. */
#define RCH_XML_WS_REFS 1u /* tab, newline, return as character references (attribute values, which
                              XML parsers otherwise normalise to blanks) */

/* The XML text of the character at s (usable in character data, attribute
 * values and HTML alike): & < > " ' as references (&amp; &lt; &gt; &quot;
 * &#39;); what XML 1.0 cannot carry (controls other than tab, newline and
 * return, DEL, invalid UTF-8, U+FFFE and U+FFFF) as &#xFFFD; (one per byte
 * of invalid UTF-8, one per noncharacter).
 * *used gets the bytes consumed (>= 1 while *s != 0). out: scratch (8). */
const char *rch_xml_piece(char out[8], const char *s, size_t *used, unsigned flags);

/* s (NULL: nothing) escaped by rch_xml_piece onto f. */
void rch_xml_put(FILE *f, const char *s, unsigned flags);

/* s escaped into buf (len > 0; always NUL-terminated, cut only between whole
 * characters or references). Returns buf. */
const char *rch_xml_escape(char *buf, size_t len, const char *s, unsigned flags);

/* The one shell quoting: argv (argc words) joined by blanks into buf, each
 * word that holds a blank, a quote or a shell character single-quoted, as
 * a user would type it (the report's command line, the next step a command
 * prints); a line that does not fit ends in " ... (cut)", never cut
 * silently. Returns buf. */
const char *rch_shell_join(char *buf, size_t len, int argc, const char *const *argv);

#endif
