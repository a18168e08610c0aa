/PROG  BAD
/MN
   1:  L PR[1] 100mm/sec FINE Offset,PR[2] ;
/POS
/END
