MODULE AliasOnly
  ! rcal compensate test module (issue 33): a robtarget declared with an ALIAS type
  LOCAL ALIAS robtarget mypos;
  CONST mypos pAlias:=[[352.333,-281.345,322.200],[0.026931,-0.692142,-0.590772,-0.413767],[-1,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    MoveL pAlias, v100, fine, tool0;
  ENDPROC
ENDMODULE
