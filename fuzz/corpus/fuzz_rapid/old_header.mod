%%%
  VERSION:1
  LANGUAGE:ENGLISH
%%%
MODULE old
  CONST jointtarget j:=[[-1,+2,3.5e1,.5,- 4,6],[9E9,9E9,9E9,9E9,9E9,9E9]];
  CONST string s:="[[1,2,3,4,5,6],[1,1,1,1,1,1]]";
ENDMODULE
