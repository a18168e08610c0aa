MODULE rcal_plan
    ! rcal poses --count 8 --seed 4: 2 outlet(s), split
    ! 8 poses; at each: MoveAbsJ (fine), a message on the pendant, WaitTime <T> s while rcal acquire reads the cable length
    CONST jointtarget rcal_p0:=[[-50.0100,69.7300,-41.0700,-123.4100,38.5700,-54.8500],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p1:=[[30.3200,90.4800,11.9400,23.9200,-7.0400,-4.1700],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p2:=[[-34.5500,78.6400,-94.4400,111.2500,100.5000,-18.6100],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p3:=[[-35.6300,59.4800,33.7300,151.4800,59.0100,-6.0200],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p4:=[[5.1800,-100.4500,-62.1000,-88.0400,50.3000,48.3500],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p5:=[[5.0100,-102.9000,-104.6700,18.5000,57.2500,-101.8000],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p6:=[[60.1600,-82.4600,-98.1000,80.7700,-20.7000,-260.4400],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p7:=[[-121.0200,86.6800,-73.5200,138.1600,17.4600,-119.7500],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST num rcal_settle_s:=5;

    PROC rcal_outlet0()
        MoveAbsJ rcal_p0\NoEOffs, v100, fine, tool0;
        TPWrite "rcal pose 0 outlet 0";
        WaitTime rcal_settle_s;
        MoveAbsJ rcal_p1\NoEOffs, v100, fine, tool0;
        TPWrite "rcal pose 1 outlet 0";
        WaitTime rcal_settle_s;
        MoveAbsJ rcal_p2\NoEOffs, v100, fine, tool0;
        TPWrite "rcal pose 2 outlet 0";
        WaitTime rcal_settle_s;
        MoveAbsJ rcal_p3\NoEOffs, v100, fine, tool0;
        TPWrite "rcal pose 3 outlet 0";
        WaitTime rcal_settle_s;
    ENDPROC

    PROC rcal_outlet1()
        MoveAbsJ rcal_p4\NoEOffs, v100, fine, tool0;
        TPWrite "rcal pose 4 outlet 1";
        WaitTime rcal_settle_s;
        MoveAbsJ rcal_p5\NoEOffs, v100, fine, tool0;
        TPWrite "rcal pose 5 outlet 1";
        WaitTime rcal_settle_s;
        MoveAbsJ rcal_p6\NoEOffs, v100, fine, tool0;
        TPWrite "rcal pose 6 outlet 1";
        WaitTime rcal_settle_s;
        MoveAbsJ rcal_p7\NoEOffs, v100, fine, tool0;
        TPWrite "rcal pose 7 outlet 1";
        WaitTime rcal_settle_s;
    ENDPROC

    PROC main()
        VAR num k;
        TPReadNum k, "rcal: the encoder stands at which outlet?";
        TEST k
        CASE 0:
            rcal_outlet0;
        CASE 1:
            rcal_outlet1;
        DEFAULT:
            TPWrite "rcal: no such outlet in this plan";
        ENDTEST
    ENDPROC
ENDMODULE
