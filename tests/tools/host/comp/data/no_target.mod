MODULE NoTarget
  ! rcal compensate test module (issue 33): no jointtarget or robtarget at all
  PERS tooldata tGrip:=[TRUE,[[12,-8,160],[0.965926,0,0.258819,0]],[1,[0,0,60],[1,0,0,0],0,0,0]];
  PROC main()
    MoveL pElsewhere, v100, fine, tGrip;
  ENDPROC
ENDMODULE
