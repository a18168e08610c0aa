/* SPDX-License-Identifier: MIT */
/* rt_rsi.h - KUKA RSI (Robot Sensor Interface) as rcal-rt speaks it: the
 * robot's <Rob> datagram decoded, the <Sen> answer written, the names both
 * use read from RSI's own Ethernet configuration file (docs/rsi.md).
 * XML through expat. No sockets here (rt_rsi_loop.c has them): the decoder
 * is what fuzz/fuzz_rsi.c drives.
 * Memory: rt_rsi_dec owns one expat parser (created once, reset per
 * datagram); everything else is the caller's. */
#ifndef RT_RSI_H
#define RT_RSI_H

#include <stddef.h>

#define RT_RSI_NAX 6
#define RT_RSI_NAME 48      /* longest tag, attribute or SENTYPE name + 1 */
#define RT_RSI_MAX_DGRAM 8192 /* a longer datagram is refused (a Rob of every DEF_ object is ~1 kB) */
#define RT_RSI_MAX_REPLY 512

typedef enum rt_rsi_status {
    RT_RSI_OK = 0,
    RT_RSI_ERR_XML,      /* not well-formed XML (expat's message), or a DOCTYPE */
    RT_RSI_ERR_ROOT,     /* the root element is not the robot's (Rob) */
    RT_RSI_ERR_IPOC,     /* no IPOC, two, or not a decimal counter */
    RT_RSI_ERR_TOO_LONG, /* over RT_RSI_MAX_DGRAM bytes */
    RT_RSI_ERR_SETPOINT, /* the setpoint element missing, doubled, an axis missing or not a finite number */
    RT_RSI_ERR_CONFIG,   /* the configuration file: what and where in the message */
    RT_RSI_ERR_NOMEM
} rt_rsi_status;

const char *rt_rsi_strerror(rt_rsi_status st);

/* The names RSI's configuration file gives (defaults: kuka_experimental's
 * and KUKA's examples): <Rob>, <Sen Type="ImFree">, <ASPos A1..A6>
 * (DEF_ASPos), <AIPos A1..A6> (DEF_AIPos), <AK A1..A6> (RECEIVE AK.A1..6),
 * <IPOC>, <Delay D> (DEF_Delay). */
typedef struct rt_rsi_names {
    char root_in[RT_RSI_NAME];  /* Rob */
    char root_out[RT_RSI_NAME]; /* Sen */
    char sentype[RT_RSI_NAME];  /* ImFree: the CONFIG's SENTYPE */
    char set_tag[RT_RSI_NAME];  /* ASPos */
    char act_tag[RT_RSI_NAME];  /* AIPos */
    char ax_attr[RT_RSI_NAX][RT_RSI_NAME];   /* A1..A6 of ASPos and AIPos */
    char corr_tag[RT_RSI_NAME];              /* AK */
    char corr_attr[RT_RSI_NAX][RT_RSI_NAME]; /* A1..A6 of AK, in the order of their INDX */
    char ipoc_tag[RT_RSI_NAME];              /* IPOC */
} rt_rsi_names;

void rt_rsi_names_default(rt_rsi_names *n);

/* What the configuration file says of the sensor's socket (its CONFIG). */
typedef struct rt_rsi_net {
    char ip[64]; /* IP_NUMBER, "" when absent */
    long port;   /* PORT, -1 when absent */
} rt_rsi_net;

/* RSI's Ethernet configuration file (text, len; path for messages) into
 * names and net. Refused (RT_RSI_ERR_CONFIG, msg "path:line:col: what"):
 * not XML, ONLYSEND TRUE (the robot would not read an answer), no DEF_ASPos
 * in SEND, no RECEIVE group of six DOUBLE elements TAG.attr (several: the one
 * named AK), a name that is not an XML name. */
rt_rsi_status rt_rsi_config_read(rt_rsi_names *n, rt_rsi_net *net, char *msg, size_t msg_len, const char *text,
                                 size_t len, const char *path);

/* One <Rob> datagram, decoded. */
typedef struct rt_rsi_rob {
    unsigned long long ipoc;
    double set_deg[RT_RSI_NAX]; /* the program's setpoint (ASPos), degrees */
    double act_deg[RT_RSI_NAX]; /* the actual axes (AIPos), when has_act */
    int set_ok;                 /* all six setpoint axes present, finite */
    int has_act;
    long delay;   /* DEF_Delay's D: the robot's count of late packets; -1 when absent */
    char set_why[160]; /* when !set_ok: what is wrong, "line:col: ..." */
} rt_rsi_rob;

typedef struct rt_rsi_dec rt_rsi_dec;

/* NULL when out of memory. */
rt_rsi_dec *rt_rsi_dec_new(const rt_rsi_names *n);
void rt_rsi_dec_free(rt_rsi_dec *d);

/* Decode buf[0..len). RT_RSI_OK: the datagram is the robot's and carries its
 * IPOC (the setpoint may still be unusable: out->set_ok 0 with set_why).
 * Otherwise why ("line:col: what") says what is wrong and out->ipoc is not
 * to be used. */
rt_rsi_status rt_rsi_decode(rt_rsi_rob *out, char *why, size_t why_len, rt_rsi_dec *d, const char *buf, size_t len);

/* The answer <Sen Type=".."><AK A1=".." ../><IPOC>n</IPOC></Sen>, AK with 10
 * decimals (degrees). Returns its length, or 0 when it does not fit cap or a
 * value is not finite (nothing to send). */
size_t rt_rsi_encode(char *out, size_t cap, const rt_rsi_names *n, const double ak_deg[RT_RSI_NAX],
                     unsigned long long ipoc);

/* A latency histogram: 0.1 us bins up to 20 ms, the rest counted over. */
#define RT_RSI_HIST_BINS 200000
typedef struct rt_rsi_hist {
    unsigned long n, over;
    double max_us, sum_us;
    unsigned *bin; /* RT_RSI_HIST_BINS */
} rt_rsi_hist;
int rt_rsi_hist_init(rt_rsi_hist *h); /* 0, -1 out of memory */
void rt_rsi_hist_free(rt_rsi_hist *h);
void rt_rsi_hist_add(rt_rsi_hist *h, double us);
/* Nearest-rank percentile p (0..100) in us (the bin's upper edge; max when over). */
double rt_rsi_hist_pct(const rt_rsi_hist *h, double p);

#endif
