MODULE BadTargets
  ! every target here is one rcal cannot correct: each named with line, column and reason
  CONST robtarget pFar:=[[2000,0,500],[0.707107,0,0.707107,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST jointtarget jName:=[[10,20,q3,40,50,60],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST jointtarget jShort:=[[10,20,30,40,50],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pConf:=[[438.426,100.804,511.163],[0.174033,0.432048,0.808673,0.359297],[2,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST jointtarget jLimit:=[[10,20,100,40,50,60],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST robtarget pWobj:=[[438.426,100.804,511.163],[0.174033,0.432048,0.808673,0.359297],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    jUnknown:=[[1,2,3,4,5,6],[9E9,9E9,9E9,9E9,9E9,9E9]];
    MoveL pWobj, v100, fine, tool0 \WObj:=wobjTable;
    MoveL [[438.426,100.804,511.163],[0.174033,0.432048,0.808673,0.359297],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, tPen;
  ENDPROC
  CONST robtarget pSing:=[[0,0,800],[0,0,0,1],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
ENDMODULE
