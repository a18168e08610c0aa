MODULE RefuseExtax
  ! rcal compensate test module (issue 47): robtargets with an external axis in use (a track) are refused
  CONST robtarget pTrack:=[[352.333,-281.345,322.200],[0.026931,-0.692142,-0.590772,-0.413767],[-1,0,0,0],[1200,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pSecond:=[[365.591,-260.707,312.480],[0.081796,-0.690938,-0.567614,-0.440146],[-1,0,0,0],[9E9,9E9,-35.5,9E9,9E9,9E9]];
  CONST robtarget pName:=[[337.552,-301.177,333.463],[0.026405,0.691438,0.612279,0.382533],[-1,0,0,0],[9E9,eTrack,9E9,9E9,9E9,9E9]];
  CONST robtarget pUnused:=[[321.355,-319.860,346.263],[0.077844,0.688816,0.631904,0.346655],[-1,0,0,0],[9E+09,9E9,9.0E9,9E9,9E9,9E9]];
  PROC main()
    MoveL pTrack, v100, fine, tool0;
    MoveL pSecond, v100, fine, tool0;
    MoveL pName, v100, fine, tool0;
    MoveL pUnused, v100, fine, tool0;
  ENDPROC
ENDMODULE
