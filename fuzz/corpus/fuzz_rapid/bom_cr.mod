MODULE M  ! a comment  CONST jointtarget a := [[10,20,-30,40,50,60],[9E9,9E9,9E9,9E9,9E9,9E9]];
  MoveAbsJ [[1,2,3,4,5,6],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, tool0;ENDMODULE