frobnicate
break
break 7
break other.soml:3
break cell.nothing
delete x
print
print a + b
print nothing
bt
locals
finish
trace maybe
trace off
next
marking
