MODULE RecordAlias
  ! rcal compensate test module (issue 33): a robtarget of an ALIAS type is corrected, one inside a RECORD refused
  ALIAS robtarget mypos;
  RECORD station
    num id;
    robtarget approach;
  ENDRECORD
  CONST mypos pAlias:=[[352.333,-281.345,322.200],[0.026931,-0.692142,-0.590772,-0.413767],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST station st1:=[1,[[365.591,-260.707,312.480],[0.081796,-0.690938,-0.567614,-0.440146],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]]];
  PROC main()
    MoveL pAlias, v100, fine, tool0;
    MoveL st1.approach, v100, fine, tool0;
  ENDPROC
ENDMODULE
