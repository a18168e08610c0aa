/PROG  T
/MN
   1:  J P[1] 100% FINE ;
   2:  C P[2]
    :  P[3] 10mm/sec CNT100 ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 0,
	J1= 0.000 deg,	J2= 0.000 deg,	J3= 0.000 deg,
	J4= 0.000 deg,	J5= -90.000 deg,	J6= 0.000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X = 400.000 mm,	Y = 0.000 mm,	Z = 500.000 mm,
	W = 180.000 deg,	P = 90.000 deg,	R = 0.000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'F D B, -1, 1, 0',
	X = 400.000 mm,	Y = 10.000 mm,	Z = 500.000 mm,
	W = 180.000 deg,	P = -90.000 deg,	R = 10.000 deg
};
/END
