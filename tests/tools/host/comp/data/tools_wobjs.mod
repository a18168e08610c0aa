MODULE ToolsWobjs
  ! rcal compensate test module (issue 33): robtargets used by every motion instruction form with a
  ! declared tool (tframe turned 30 deg about y) and work object (uframe and oframe turned)
  PERS tooldata tGrip:=[TRUE,[[12,-8,160],[0.965926,0,0.258819,0]],[1,[0,0,60],[1,0,0,0],0,0,0]];
  TASK PERS wobjdata wTable:=[FALSE,TRUE,"",[[350,-120,80],[0.92388,0,0,0.382683]],[[20,10,5],[0.996195,0.087156,0,0]]];
  VAR triggdata trig1;
  VAR triggdata trig2;
  VAR robtarget pCopy;
  VAR jointtarget jCalc;
  CONST robtarget p1:=[[-181.577,-83.708,280.053],[0.280340,0.857030,0.344304,0.261465],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p2:=[[-156.914,-84.200,267.142],[0.246231,0.854907,0.329846,0.315763],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p3:=[[-132.438,-82.638,255.431],[0.208389,0.850609,0.314078,0.366598],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p4:=[[-108.470,-79.187,244.952],[0.167080,0.844210,0.297177,0.413617],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p5:=[[-109.839,-148.712,254.082],[0.277330,0.842883,0.264075,0.378023],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p6:=[[-81.914,-83.663,402.025],[0.374718,0.788551,0.317061,0.370467],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p7:=[[-56.775,-82.528,387.448],[0.328571,0.788728,0.305894,0.419975],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p8:=[[-33.772,-38.597,233.870],[0.130079,0.826754,0.204497,0.507679],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p9:=[[-32.468,-108.658,238.029],[0.240968,0.825703,0.166003,0.482278],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p10:=[[-6.867,-101.913,226.494],[0.189470,0.820230,0.145781,0.519685],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p11:=[[14.962,-40.422,370.602],[0.274417,0.766880,0.218727,0.537353],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p12:=[[37.760,-33.373,360.809],[0.216897,0.764364,0.203848,0.571969],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p13:=[[43.453,-98.948,379.158],[0.323626,0.741050,0.154318,0.567712],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p14:=[[69.622,-91.921,364.813],[0.264294,0.741102,0.138630,0.601414],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p15:=[[79.740,-40.681,207.895],[0.067321,0.788467,0.011173,0.611280],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p16:=[[95.435,19.064,348.372],[0.133363,0.739294,0.100767,0.652307],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p17:=[[104.234,-48.042,360.893],[0.237193,0.715985,0.045172,0.655031],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p18:=[[128.767,-38.096,350.418],[0.172783,0.715219,0.027802,0.676635],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p19:=[[151.567,-26.506,340.634],[0.107157,0.713055,0.010540,0.692791],[-1,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p20:=[[172.440,-13.562,331.524],[0.040751,0.709545,-0.006394,0.703452],[-1,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p21:=[[159.632,17.512,503.663],[0.236869,0.606936,0.046272,0.757219],[-1,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p22:=[[175.107,19.432,334.836],[0.069226,0.686729,-0.091714,0.717774],[-1,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p23:=[[196.025,32.713,328.740],[0.001947,0.683898,-0.109090,0.721373],[-1,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p24:=[[214.950,46.831,323.185],[0.065195,-0.679809,0.125629,-0.719602],[-1,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p25:=[[231.904,-19.060,316.302],[0.032604,0.654308,-0.192377,0.730622],[-1,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p26:=[[221.282,84.153,474.829],[0.034965,0.588678,-0.084343,0.803195],[-1,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p27:=[[240.880,98.160,466.349],[0.035625,-0.593565,0.096846,-0.798143],[-1,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  VAR robtarget pSearch:=[[258.151,113.034,458.048],[0.105390,-0.597398,0.108428,-0.787561],[-1,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pTool1:=[[321.355,-319.860,346.263],[0.077844,0.688816,0.631904,0.346655],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PERS robtarget pTool2:=[[337.552,-301.177,333.463],[0.026405,0.691438,0.612279,0.382533],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];

  PROC main()
    MoveL p1, v100, z10, tGrip\WObj:=wTable;
    MoveJ p2, v200, z10, tGrip \WObj:=wTable;
    MoveC p3, p4, v100, z5, tGrip\WObj:=wTable;
    MoveLDO p5, v100, z10, tGrip\WObj:=wTable, do1, 1;
    MoveJDO p6, v100, fine, tGrip \WObj:=wTable, do1, 0;
    MoveCDO p7, p8, v100, z10, tGrip\WObj:=wTable, do1, 1;
    MoveLAO p9, v100, z10, tGrip\WObj:=wTable, ao1, 5.5;
    MoveLGO p10, v100, z10, tGrip\WObj:=wTable, go1, 3;
    MoveLSync p11, v100, z10, tGrip\WObj:=wTable, "MyProc";
    MoveJSync p12, v100, z10, tGrip\WObj:=wTable, "MyProc";
    TriggL p13, v100, trig1, z10, tGrip\WObj:=wTable;
    TriggJ p14, v100, trig1 \T2:=trig2, fine, tGrip\WObj:=wTable;
    TriggC p15, p16, v100, trig1, z10, tGrip\WObj:=wTable;
    SearchL \Stop, di1, pSearch, p17, v100, tGrip\WObj:=wTable;
    SearchC di1 \Flanks, pSearch, p18, p19, v100, tGrip\WObj:=wTable;
    ArcL \On, p20, v100, seam1, weld1, weave1, z10, tGrip\WObj:=wTable;
    ArcC p21, p22, v100, seam1, weld1, weave1, fine, tGrip\WObj:=wTable;
    MoveL \Conc, p23 \ID:=10, v100 \T:=3, z10 \Z:=5, tGrip \WObj:=wTable \TLoad:=load1;
    IF reg1 = 1 THEN
      MoveL Offs(p24, 0, 0, 10), v100, fine, tGrip\WObj:=wTable;
    ELSE
      MoveL RelTool(p24, 0, 0, -10), v100, fine, tGrip\WObj:=wTable;
    ENDIF
    pCopy := p25;
    MoveL pCopy, v100, fine, tGrip\WObj:=wTable;
    MyProc p26;
    MoveL p26, v100, fine, tGrip\WObj:=wTable;
    jCalc := CalcJointT(p27, tGrip \WObj:=wTable);
    MoveL pTool1, v100, fine, tGrip;
    lbl: IF reg1 = 2 MoveJ pTool2, v100, fine, tGrip;
  ENDPROC

  PROC MyProc(robtarget p)
    TPWrite "at" \Pos:=p;
  ENDPROC
ENDMODULE
