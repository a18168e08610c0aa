/PROG  EVERY_FORM	  Macro
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "rcal every form";
PROG_SIZE	= 1234;
CREATE		= DATE 26-12-05  TIME 12:00:00;
MODIFIED	= DATE 26-12-05  TIME 12:00:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 24;
MEMORY_SIZE	= 1500;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/APPL
/MN
   1:  !every instruction form rcal reads ;
   2:  UFRAME_NUM=0 ;
   3:  UTOOL_NUM=0 ;
   4:  J P[1:home] 100% FINE ;
   5:  J P[2:approach] 50% CNT50 ;
   6:  L P[3] 500mm/sec FINE ;
   7:  L P[4] 2000cm/min CNT100 ACC80 ;
   8:  C P[5] 
    :  P[6] 200mm/sec FINE ;
   9:  A P[7] 100mm/sec CNT100 ;
  10:  A P[8] 100mm/sec FINE ;
  11:  // a remark ;
  12:  R[1:count]=R[1:count]+1 ;
  13:  WAIT   0.50(sec) ;
  14:  DO[1]=ON ;
  15:  CALL SUB_PROG ;
  16:  UFRAME_NUM=1 ;
  17:  UTOOL_NUM=1 ;
  18:  L P[9] 100mm/sec FINE Wjnt ;
  19:  J P[10] 30% CNT20 ;
  20:  J P[11] 100% FINE ;
  21:  IF R[1]<3,JMP LBL[1] ;
  22:  LBL[1] ;
  23:  PR[1]=LPOS ;
  24:  MESSAGE[done P[1] here] ;
/POS
P[1:"home"]{
   GP1:
	UF : 0, UT : 0,	
	J1=     0.000 deg,	J2=     0.000 deg,	J3=     0.000 deg,
	J4=     0.000 deg,	J5=   -90.000 deg,	J6=     0.000 deg
};
P[2:"approach"]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F U T, 0, 0, 0',
	X =   547.561  mm,	Y =    70.442  mm,	Z =   561.896  mm,
	W =   136.433 deg,	P =   -19.916 deg,	R =    54.255 deg
};
P[3]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 1',
	X =   395.948  mm,	Y =  -269.189  mm,	Z =   820.949  mm,
	W =    45.201 deg,	P =    36.264 deg,	R =    -2.699 deg
};
P[4]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F U T, 0, 0, -1',
	X =   162.064  mm,	Y =   254.595  mm,	Z =   632.796  mm,
	W =  -173.739 deg,	P =    26.177 deg,	R =  -127.203 deg
};
P[5]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F U T, 0, 1, 0',
	X =   572.323  mm,	Y =    53.571  mm,	Z =   849.756  mm,
	W =   -10.529 deg,	P =    28.456 deg,	R =   -11.338 deg
};
P[6]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F D T, 0, 0, 0',
	X =    34.590  mm,	Y =     0.024  mm,	Z =   176.158  mm,
	W =   169.488 deg,	P =    -6.275 deg,	R =    42.685 deg
};
P[7]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =   462.593  mm,	Y =  -428.162  mm,	Z =   152.251  mm,
	W =  -159.823 deg,	P =   -76.133 deg,	R =   -83.880 deg
};
P[8]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F D B, 0, 0, 0',
	X =  -396.908  mm,	Y =   -97.107  mm,	Z =   882.497  mm,
	W =     4.018 deg,	P =    11.554 deg,	R =  -177.486 deg
};
P[9]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   370.707  mm,	Y =   242.037  mm,	Z =   504.081  mm,
	W =  -119.508 deg,	P =    -7.557 deg,	R =   -36.667 deg
};
P[10]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U B, 0, 0, 0',
	X =  -230.917  mm,	Y =   239.553  mm,	Z =   749.635  mm,
	W =   179.310 deg,	P =   -86.347 deg,	R =   -14.819 deg
};
P[11]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -20.000 deg,	J2=     5.000 deg,	J3=    20.000 deg,
	J4=    45.000 deg,	J5=   -30.000 deg,	J6=   300.000 deg
};
/END
