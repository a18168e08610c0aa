/* SPDX-License-Identifier: MIT */
/* fuzz_rsi.c - rcal-rt's KUKA RSI decoder (firmware_host/rt_rsi.c): a <Rob>
 * datagram as the robot would send it, and RSI's Ethernet configuration
 * file. Input byte 0 chooses: even, the datagram decoder (then its answer
 * encoded); odd, the configuration reader. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "rt_rsi.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static rt_rsi_dec *dec;
    static rt_rsi_names names;
    if (!dec) {
        rt_rsi_names_default(&names);
        dec = rt_rsi_dec_new(&names);
        FZ_CHECK(dec != NULL);
    }
    if (size < 1)
        return 0;
    const char *buf = (const char *)data + 1;
    const size_t len = size - 1;
    if ((data[0] & 1u) == 0) {
        rt_rsi_rob r;
        char why[192];
        memset(why, 'x', sizeof why);
        const rt_rsi_status st = rt_rsi_decode(&r, why, sizeof why, dec, buf, len);
        FZ_CHECK(memchr(why, '\0', sizeof why) != NULL);
        FZ_CHECK(memchr(r.set_why, '\0', sizeof r.set_why) != NULL);
        if (st == RT_RSI_OK) {
            FZ_CHECK(r.ipoc < 1000000000000000000ull);
            if (r.set_ok)
                for (int i = 0; i < RT_RSI_NAX; ++i)
                    FZ_CHECK(isfinite(r.set_deg[i]));
            else
                FZ_CHECK(r.set_why[0] != '\0');
            /* the answer to it always fits and names the IPOC */
            char out[RT_RSI_MAX_REPLY];
            const double ak[RT_RSI_NAX] = {0, 0, 0, 0, 0, 0};
            const size_t n = rt_rsi_encode(out, sizeof out, &names, ak, r.ipoc);
            FZ_CHECK(n > 0 && n < sizeof out && strstr(out, "<IPOC>") != NULL);
        } else {
            FZ_CHECK(!r.set_ok);
            FZ_CHECK(why[0] != '\0' || st == RT_RSI_ERR_NOMEM);
        }
    } else {
        rt_rsi_names n;
        rt_rsi_net net;
        char msg[512];
        memset(msg, 'x', sizeof msg);
        const rt_rsi_status st = rt_rsi_config_read(&n, &net, msg, sizeof msg, buf, len, "fuzz.xml");
        if (st == RT_RSI_OK) {
            FZ_CHECK(n.corr_tag[0] != '\0' && n.sentype[0] != '\0');
            for (int i = 0; i < RT_RSI_NAX; ++i)
                FZ_CHECK(n.corr_attr[i][0] != '\0');
            FZ_CHECK(net.port == -1 || (net.port >= 1 && net.port <= 65535));
        } else
            FZ_CHECK(memchr(msg, '\0', sizeof msg) != NULL);
    }
    return 0;
}
