MODULE EveryForm
  ! rcal compensate test module (issue 21): every joint target and robtarget form.
  ! In a comment a target stays as it is: MoveAbsJ [[1,2,3,4,5,6],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, z10, tool0;
  CONST jointtarget jHome:=[[0,0,0,0,30,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST jointtarget jA:=[[10,20,-30,40,50,60],[9E9,9E9,9E9,9E9,9E9,9E9]]; CONST jointtarget jB := [[-15,5,10,-20,35,-45],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PERS jointtarget jLong:=[[ 25.5, -12.25,
                             18, ! a comment inside the aggregate
                             -33.125, 44, 90 ],
                           [9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  VAR jointtarget jC;
  CONST jointtarget jArr{2}:=[[[5,10,15,0,45,0],[9E9,9E9,9E9,9E9,9E9,9E9]],[[-5,-10,-15,0,-45,0],[9E9,9E9,9E9,9E9,9E9,9E9]]];
  CONST num table{2,6}:=[[1,2,3,4,5,6],[1,2,3,4,5,6]];
  CONST speeddata vSlow:=[50,500,5000,1000];
  PERS tooldata tPen:=[TRUE,[[0,0,150],[1,0,0,0]],[0.5,[0,0,50],[1,0,0,0],0,0,0]];
  CONST robtarget pHome:=[[374,0,630],[0.707107,0,0.707107,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget p10:=[[438.426,100.804,511.163],[0.174033,0.432048,0.808673,0.359297],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PERS robtarget p20:=[[367.691,-185.567,458.226],
                       [0.595070,0.462589,0.580228,0.308608],
                       [-1,-1,1,1],
                       [9E9,9E9,9E9,9E9,9E9,9E9]];
  VAR robtarget pA;
  CONST robtarget path{2}:=[[[451.586,164.364,477.968],[0.250000,-0.084186,0.962250,0.066987],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]],
                            [[456.503,217.767,468.878],[0.262745,-0.021439,0.952781,0.150711],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]]];

  PROC main()
    TPWrite "a string is copied: jointtarget j:=[[1,2,3,4,5,6],[0,0,0,0,0,0]]; "" [";
    MoveAbsJ jHome\NoEOffs, v100, fine, tool0;
    MoveAbsJ [[5,10,15,0,45,0],[9E9,9E9,9E9,9E9,9E9,9E9]]\NoEOffs, v100, z10, tool0;
    MoveAbsJ jA, v100, z10, tool0; MoveAbsJ [[-5,-10,-15,0,-45,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, z10, tool0;
    jC:=[[1,2,3,4,5,6],[9E9,9E9,9E9,9E9,9E9,9E9]];
    MoveAbsJ jC, vSlow, fine, tool0;
    MoveJ p10, v200, z10, tool0;
    MoveL [[163.472,178.784,493.487],[0.187097,-0.968776,0.157608,-0.040333],[0,0,-2,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, tool0;
    MoveC [[307.366,-415.187,542.366],[0.612797,-0.391397,0.380986,-0.571085],[-1,1,-3,0],[9E9,9E9,9E9,9E9,9E9,9E9]],
          [[-185.512,114.324,621.118],[0.224186,-0.797762,0.175627,0.531480],[1,-1,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, z5, tool0;
    pA:=[[429.897,26.882,517.769],[0.394973,0.089991,0.914238,-0.008135],[0,-1,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
    MoveL pA, v100, fine, tool0;
    MoveL Offs(p10,0,0,50), v100, fine, tool0;
    MoveL path{1}, v100, z1, tool0;
    MoveJ pHome, v200, fine, tool0;
  ENDPROC
ENDMODULE
