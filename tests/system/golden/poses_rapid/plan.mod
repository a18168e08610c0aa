MODULE rcal_plan
    ! rcal poses --count 8 --seed 4: 2 outlet(s), split
    ! 8 poses; at each: MoveAbsJ (fine), a message on the pendant, WaitTime <T> s while rcal acquire reads the cable length
    CONST jointtarget rcal_p0:=[[107.2700,-64.8200,-29.4600,91.1300,-90.6400,-22.6100],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p1:=[[-10.5000,65.0000,49.0000,82.8200,-72.4000,-199.8100],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p2:=[[-66.4500,63.3400,-39.6600,-33.1000,-6.0200,-347.2600],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p3:=[[41.2700,64.4400,38.7600,-142.2600,-60.4000,-283.3200],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p4:=[[60.1600,-82.4600,-98.1000,80.7700,-20.7000,99.5600],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p5:=[[50.3200,-96.7200,-59.4400,119.6200,97.1800,-7.4900],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p6:=[[-121.0200,86.6800,-73.5200,138.1600,17.4600,-119.7500],[9E9,9E9,9E9,9E9,9E9,9E9]];
    CONST jointtarget rcal_p7:=[[-146.0800,65.3000,-14.9000,30.0300,19.0000,-227.9400],[9E9,9E9,9E9,9E9,9E9,9E9]];
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
