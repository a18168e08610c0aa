MODULE RefuseUses
  ! rcal compensate test module (issue 33): robtargets whose tool or work object rcal cannot tell, each refused
  PERS tooldata tGrip:=[TRUE,[[12,-8,160],[0.965926,0,0.258819,0]],[1,[0,0,60],[1,0,0,0],0,0,0]];
  PERS wobjdata wConv:=[FALSE,FALSE,"CNV1",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];
  PERS tooldata tools{2};
  CONST robtarget pProc:=[[321.355,-319.860,346.263],[0.077844,0.688816,0.631904,0.346655],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pLate:=[[337.552,-301.177,333.463],[0.026405,0.691438,0.612279,0.382533],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pTwo:=[[352.333,-281.345,322.200],[0.026931,-0.692142,-0.590772,-0.413767],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pConv:=[[365.591,-260.707,312.480],[0.081796,-0.690938,-0.567614,-0.440146],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pNoWobj:=[[-181.577,-83.708,280.053],[0.280340,0.857030,0.344304,0.261465],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pToolExpr:=[[-156.914,-84.200,267.142],[0.246231,0.854907,0.329846,0.315763],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pSpot:=[[-132.438,-82.638,255.431],[0.208389,0.850609,0.314078,0.366598],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    Draw pProc, tGrip;
    %"Draw" + "2"% pLate;
    MoveL pTwo, v100, fine, tGrip;
    MoveL pTwo, v100, fine, tool0;
    MoveL pConv, v100, fine, tGrip\WObj:=wConv;
    MoveL pNoWobj, v100, fine, tGrip\WObj:=wElse;
    MoveL pToolExpr, v100, fine, tools{1};
    SpotL pSpot, vmax, gun1, tGrip;
  ENDPROC
  PROC Draw(robtarget p, PERS tooldata t)
    MoveL p, v100, fine, t;
  ENDPROC
ENDMODULE
