/* SPDX-License-Identifier: MIT */
/* rch_poses_link.c - a plan as a robot program that speaks rcal-link/1 (docs/controller-link.md) to
 * `rcal acquire --controller`: ABB RAPID (SocketCreate/SocketConnect/SocketSend/SocketReceive, MoveAbsJ,
 * WaitRob \ZeroSpeed, CJointT) and UR URScript (socket_open, movej, get_actual_joint_positions). The
 * program connects, says HELLO, then obeys NEXT/BACK/AGAIN J (move to plan pose J, stand still, report
 * AT J with its own joints) until STOP. Depends on: stdio only. Errors: -1 when a write failed. */
#include "rch_poses_link.h"

#define PI_ 3.14159265358979323846

/* The outlet label each AT reports: the plan's column with several outlets, -1 with one. */
static int outlets_many(const unsigned char *lab, size_t n)
{
    for (size_t i = 1; lab && i < n; ++i)
        if (lab[i] != lab[0])
            return 1;
    return 0;
}

/* FUNC num NAME(num j): the label of plan pose j (lab NULL: -1 for every pose). */
static void rapid_label_func(FILE *f, const char *name, const unsigned char *lab, size_t n)
{
    fprintf(f, "    FUNC num %s(num j)\n", name);
    if (lab) {
        fprintf(f, "        TEST j\n");
        for (size_t i = 0; i < n; ++i)
            fprintf(f, "        CASE %zu:\n            RETURN %u;\n", i, (unsigned)lab[i]);
        fprintf(f, "        ENDTEST\n");
    }
    fprintf(f, "        RETURN -1;\n    ENDFUNC\n\n");
}

/* NAME = [l0, l1, ...]: the label of each plan pose (lab NULL: -1). */
static void urscript_label_list(FILE *f, const char *name, const unsigned char *lab, size_t n)
{
    fprintf(f, "  %s = [", name);
    for (size_t i = 0; i < n; ++i)
        fprintf(f, "%s%d", i ? ", " : "", lab ? (int)lab[i] : -1);
    fprintf(f, "]\n");
}

int rch_poses_write_rapid_link(FILE *f, const rc_sample *rows, const unsigned char *outlet_label,
                               const unsigned char *point_label, size_t n, const char *host, unsigned port,
                               const char *comment)
{
    const int many = outlets_many(outlet_label, n);
    fprintf(f, "MODULE rcal_link\n");
    if (comment)
        fprintf(f, "    ! %s\n", comment);
    fprintf(f, "    ! rcal-link/1 (docs/controller-link.md): run `rcal acquire --controller tcp:%s:%u ...` first; this\n"
               "    ! program connects to %s:%u, moves where rcal says (NEXT/BACK/AGAIN J) and reports AT J with\n"
               "    ! CJointT after WaitRob \\ZeroSpeed, until STOP.\n", host, port, host, port);
    for (size_t i = 0; i < n; ++i) {
        fprintf(f, "    CONST jointtarget rcal_p%zu:=[[", i);
        for (int j = 0; j < RC_NJ; ++j)
            fprintf(f, "%s%.4f", j ? "," : "", rows[i].q_rad[j] * 180.0 / PI_);
        fprintf(f, "],[9E9,9E9,9E9,9E9,9E9,9E9]];\n");
    }
    fprintf(f, "    CONST num rcal_n:=%zu;\n", n);
    fprintf(f, "    VAR socketdev rcal_sock;\n");
    fprintf(f, "    VAR string rcal_buf:=\"\";\n");
    fprintf(f, "    VAR intnum rcal_hb;\n\n");
    /* the plan pose j */
    fprintf(f, "    PROC rcal_move(num j)\n        TEST j\n");
    for (size_t i = 0; i < n; ++i)
        fprintf(f, "        CASE %zu:\n            MoveAbsJ rcal_p%zu\\NoEOffs, v200, fine, tool0;\n", i, i);
    fprintf(f, "        ENDTEST\n        WaitRob \\ZeroSpeed;\n    ENDPROC\n\n");
    rapid_label_func(f, "rcal_outlet", many ? outlet_label : NULL, n);
    rapid_label_func(f, "rcal_point", point_label, n);
    /* one line from the socket (one byte per SocketReceive: RAPID strings hold 80 characters; a longer
     * line, a FAULT with its text, is cut and its pieces ignored) */
    fprintf(f, "    FUNC string rcal_line()\n"
               "        VAR string chunk;\n        VAR string line;\n        VAR num p;\n"
               "        WHILE TRUE DO\n"
               "            p:=StrFind(rcal_buf, 1, \"\\0A\");\n"
               "            IF p <= StrLen(rcal_buf) THEN\n"
               "                line:=StrPart(rcal_buf, 1, p - 1);\n"
               "                IF p < StrLen(rcal_buf) THEN\n"
               "                    rcal_buf:=StrPart(rcal_buf, p + 1, StrLen(rcal_buf) - p);\n"
               "                ELSE\n                    rcal_buf:=\"\";\n                ENDIF\n"
               "                RETURN line;\n"
               "            ENDIF\n"
               "            IF StrLen(rcal_buf) > 78 rcal_buf:=\"\";\n"
               "            SocketReceive rcal_sock \\Str:=chunk \\ReadNoOfBytes:=1 \\Time:=30;\n"
               "            rcal_buf:=rcal_buf + chunk;\n"
               "        ENDWHILE\n    ENDFUNC\n\n");
    fprintf(f, "    PROC rcal_at(num j)\n        VAR jointtarget jt;\n"
               "        jt:=CJointT();\n"
               "        SocketSend rcal_sock \\Str:=\"AT \" + NumToStr(j, 0) + \" \" + NumToStr(rcal_outlet(j), 0) + "
               "\" \" + NumToStr(rcal_point(j), 0) + \" \" + NumToStr(jt.robax.rax_1, 5) + \" \" + NumToStr(jt.robax.rax_2, 5) + \" \";\n"
               "        SocketSend rcal_sock \\Str:=NumToStr(jt.robax.rax_3, 5) + \" \" + NumToStr(jt.robax.rax_4, 5) "
               "+ \" \" + NumToStr(jt.robax.rax_5, 5) + \" \" + NumToStr(jt.robax.rax_6, 5) + \"\\0A\";\n"
               "    ENDPROC\n\n");
    fprintf(f, "    TRAP rcal_heartbeat\n        SocketSend rcal_sock \\Str:=\"HB\\0A\";\n    ENDTRAP\n\n");
    fprintf(f, "    PROC main()\n        VAR string line;\n        VAR num j;\n        VAR bool ok;\n"
               "        SocketCreate rcal_sock;\n"
               "        SocketConnect rcal_sock, \"%s\", %u \\Time:=60;\n"
               "        SocketSend rcal_sock \\Str:=\"HELLO rcal-link/1 abb\\0A\";\n"
               "        CONNECT rcal_hb WITH rcal_heartbeat;\n        ITimer 1, rcal_hb;\n"
               "        WHILE TRUE DO\n"
               "            line:=rcal_line();\n"
               "            IF StrPart(line, 1, 4) = \"STOP\" THEN\n"
               "                IDelete rcal_hb;\n                SocketClose rcal_sock;\n                RETURN;\n"
               "            ENDIF\n"
               "            IF StrLen(line) > 5 AND (StrPart(line, 1, 5) = \"NEXT \" OR StrPart(line, 1, 5) = \"BACK \") "
               "THEN\n"
               "                ok:=StrToVal(StrPart(line, 6, StrLen(line) - 5), j);\n"
               "                IF ok AND j >= 0 AND j < rcal_n THEN\n"
               "                    rcal_move j;\n                    rcal_at j;\n"
               "                ENDIF\n"
               "            ENDIF\n"
               "            IF StrLen(line) > 6 AND StrPart(line, 1, 6) = \"AGAIN \" THEN\n"
               "                ok:=StrToVal(StrPart(line, 7, StrLen(line) - 6), j);\n"
               "                IF ok rcal_at j;\n"
               "            ENDIF\n"
               "        ENDWHILE\n"
               "    ERROR\n"
               "        IF ERRNO = ERR_SOCK_CLOSED OR ERRNO = ERR_SOCK_TIMEOUT THEN\n"
               "            ! the link is lost: connect again, rcal resends the command in force\n"
               "            SocketClose rcal_sock;\n            WaitTime 1;\n            SocketCreate rcal_sock;\n"
               "            SocketConnect rcal_sock, \"%s\", %u \\Time:=60;\n"
               "            rcal_buf:=\"\";\n"
               "            SocketSend rcal_sock \\Str:=\"HELLO rcal-link/1 abb\\0A\";\n"
               "            RETRY;\n"
               "        ENDIF\n"
               "    ENDPROC\nENDMODULE\n", host, port, host, port);
    return ferror(f) ? -1 : 0;
}

int rch_poses_write_urscript_link(FILE *f, const rc_sample *rows, const unsigned char *outlet_label,
                                  const unsigned char *point_label, size_t n, const char *host, unsigned port,
                                  const char *comment)
{
    const int many = outlets_many(outlet_label, n);
    fprintf(f, "# %s\n", comment ? comment : "rcal poses");
    fprintf(f, "# rcal-link/1 (docs/controller-link.md): run `rcal acquire --controller tcp:%s:%u ...` first; this\n"
               "# program connects to %s:%u, moves where rcal says (NEXT/BACK/AGAIN J) and reports AT J with\n"
               "# get_actual_joint_positions() once the arm is steady, until STOP.\n", host, port, host, port);
    fprintf(f, "def rcal_link():\n");
    fprintf(f, "  rcal_plan = [");
    for (size_t i = 0; i < n; ++i) {
        fprintf(f, "%s[", i ? ", " : "");
        for (int j = 0; j < RC_NJ; ++j)
            fprintf(f, "%s%.7f", j ? ", " : "", rows[i].q_rad[j]);
        fprintf(f, "]");
    }
    fprintf(f, "]\n");
    urscript_label_list(f, "rcal_outlet", many ? outlet_label : NULL, n);
    urscript_label_list(f, "rcal_point", point_label, n);
    fprintf(f, "  rcal_n = %zu\n", n);
    fprintf(f, "  thread rcal_heartbeat():\n"
               "    while True:\n"
               "      sleep(1.0)\n"
               "      socket_send_line(\"HB\", \"rcal\")\n"
               "    end\n"
               "  end\n");
    fprintf(f, "  def rcal_at(j):\n"
               "    q = get_actual_joint_positions()\n"
               "    line = str_cat(\"AT \", str_cat(to_str(j), str_cat(\" \", str_cat(to_str(rcal_outlet[j]), "
               "str_cat(\" \", to_str(rcal_point[j]))))))\n"
               "    i = 0\n"
               "    while i < 6:\n"
               "      line = str_cat(line, str_cat(\" \", to_str(r2d(q[i]))))\n"
               "      i = i + 1\n"
               "    end\n"
               "    socket_send_line(line, \"rcal\")\n"
               "  end\n");
    fprintf(f, "  def rcal_connect():\n"
               "    while not socket_open(\"%s\", %u, \"rcal\"):\n"
               "      sleep(1.0)\n"
               "    end\n"
               "    socket_send_line(\"HELLO rcal-link/1 ur\", \"rcal\")\n"
               "  end\n", host, port);
    fprintf(f, "  rcal_connect()\n"
               "  hb = run rcal_heartbeat()\n"
               "  while True:\n"
               "    line = socket_read_line(\"rcal\", timeout=30)\n"
               "    if line == \"\":\n"
               "      socket_close(\"rcal\")\n"
               "      rcal_connect()\n"
               "    elif str_find(line, \"STOP\") == 0:\n"
               "      kill hb\n"
               "      socket_close(\"rcal\")\n"
               "      halt\n"
               "    elif str_find(line, \"NEXT \") == 0 or str_find(line, \"BACK \") == 0:\n"
               "      j = to_num(str_sub(line, 5))\n"
               "      if j >= 0 and j < rcal_n:\n"
               "        movej(rcal_plan[j], a=1.0, v=0.5)\n"
               "        while not is_steady():\n"
               "          sync()\n"
               "        end\n"
               "        rcal_at(j)\n"
               "      end\n"
               "    elif str_find(line, \"AGAIN \") == 0:\n"
               "      rcal_at(to_num(str_sub(line, 6)))\n"
               "    end\n"
               "  end\n"
               "end\n"
               "rcal_link()\n");
    return ferror(f) ? -1 : 0;
}
